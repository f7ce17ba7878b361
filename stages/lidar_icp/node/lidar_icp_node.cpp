#include "stages/lidar_icp/node/lidar_icp_node.hpp"

#include "runtime/channels.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/motion_message.hpp"

namespace fusecal {

std::string LidarIcpNodeSettings::Validate() const {
  if (previous_stations < 1 || previous_stations > 10) return "previous_stations: must be in [1, 10]";
  return registration.Validate();
}

LidarIcpNodeSettings ReadLidarIcpNodeSettings(ConfigReader r) {
  LidarIcpNodeSettings s;
  auto& g = s.registration;
  r.Get("previous_stations", &s.previous_stations);
  r.Get("min_range_m", &g.min_range_m);
  r.Get("max_range_m", &g.max_range_m);
  r.Get("voxel_size_m", &g.voxel_size_m);
  r.Get("max_tilt_deg", &g.max_tilt_deg);
  r.Get("max_correspondence_m", &g.max_correspondence_m);
  r.Get("min_correspondence_m", &g.min_correspondence_m);
  r.Get("max_source_points", &g.max_source_points);
  r.Get("min_fitness", &g.min_fitness);
  r.Get("num_threads", &g.num_threads);
  r.Finish();
  r.FailIfInvalid(s.Validate());
  return s;
}

LidarIcpNode::LidarIcpNode(LidarIcpNodeSettings settings)
    : StationPairNode<PointCloud>("lidar", ForCamera(channels::kStation, settings.station_camera),
                                  channels::kLidarMotion, settings.previous_stations),
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
  motion_t motion =
      result.usable()
          ? MakeMotion(previous_id, station.id, "lidar", result.T_li_lj, true, result.covariance, station.utime)
          : MakeFailedMotion(previous_id, station.id, "lidar", result.failure_reason.text, station.utime);
  motion.fitness = result.fitness;
  motion.rmse = result.inlier_rms_m;
  motion.iterations = result.iterations;
  motion.inliers = static_cast<int32_t>(result.inliers);
  motion.seconds = result.seconds;
  return motion;
}

}  // namespace fusecal
