#include "lidar_icp/node/lidar_icp_node.hpp"

#include "formats/conversions.hpp"
#include "formats/motion_message.hpp"
#include "runtime/channels.hpp"

namespace fusecal {

LidarIcpNodeSettings ReadLidarIcpNodeSettings(ConfigReader r) {
  LidarIcpNodeSettings s;
  auto& g = s.registration;
  r.Get("previous_stations", &s.previous_stations, InRange(1, 10));
  r.Get("min_range_m", &g.min_range_m, NonNegative<double>());
  r.Get("max_range_m", &g.max_range_m, Positive<double>());
  r.Get("voxel_size_m", &g.voxel_size_m, NonNegative<double>());
  r.Get("max_tilt_deg", &g.max_tilt_deg, InRange(0.0, 180.0));
  r.Get("max_correspondence_m", &g.max_correspondence_m, Positive<double>());
  r.Get("min_fitness", &g.min_fitness, InRange(0.0, 1.0));
  r.Get("num_threads", &g.num_threads, NonNegative<int>());
  r.Finish();
  const std::string error = g.Validate();
  if (!error.empty()) r.FailSection(error);
  return s;
}

LidarIcpNode::LidarIcpNode(LidarIcpNodeSettings settings)
    : StationPairNode<PointCloud>("lidar", channels::kLidarMotion, settings.previous_stations),
      settings_(std::move(settings)) {}

PointCloud LidarIcpNode::Prepare(const station_t& station) {
  try {
    return CloudFromMsg(station.cloud);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("bad scan: ") + e.what());
  }
}

motion_t LidarIcpNode::Pair(int previous_id, const PointCloud& previous, const station_t& station,
                            const PointCloud& current) {
  const auto result = lidar_icp::Register(previous, current, settings_.registration);
  motion_t motion = result.converged
                        ? MakeMotion(previous_id, station.id, "lidar", result.T_li_lj, true, result.covariance,
                                     station.utime)
                        : MakeFailedMotion(previous_id, station.id, "lidar", result.failure_reason, station.utime);
  motion.fitness = result.fitness;
  motion.rmse = result.inlier_rms_m;
  motion.iterations = result.iterations;
  motion.inliers = static_cast<int32_t>(result.inliers);
  motion.seconds = result.seconds;
  return motion;
}

}  // namespace fusecal
