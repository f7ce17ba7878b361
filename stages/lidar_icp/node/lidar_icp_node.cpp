#include "lidar_icp/node/lidar_icp_node.hpp"

#include "runtime/channels.hpp"
#include "runtime/conversions.hpp"
#include "runtime/motion_message.hpp"

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

void LidarIcpNode::Start(Bus& bus) {
  subscriptions_.push_back(bus.Subscribe<station_t>(
      channels::kStation, std::function<void(const station_t&)>([this, &bus](const station_t& s) { OnStation(bus, s); })));
}

void LidarIcpNode::OnStation(Bus& bus, const station_t& station) {
  if (const auto seen = published_.find(station.id); seen != published_.end()) {
    for (const auto& motion : seen->second) bus.Publish(channels::kLidarMotion, motion);
    return;
  }
  published_[station.id];
  ++stations_;
  PointCloud cloud;
  try {
    cloud = CloudFromMsg(station.cloud);
  } catch (const std::exception& e) {
    ++failures_;
    throw std::runtime_error("station " + std::to_string(station.id) + ": bad scan: " + e.what());
  }
  state_ = "registering";
  for (const auto& [previous_id, previous_cloud] : previous_) {
    const auto result = lidar_icp::Register(previous_cloud, cloud, settings_.registration);
    busy_s_ += result.seconds;
    motion_t motion = result.converged
                          ? MakeMotion(previous_id, station.id, "lidar", result.T_li_lj, true, result.covariance,
                                       station.utime)
                          : MakeFailedMotion(previous_id, station.id, "lidar", result.failure_reason, station.utime);
    motion.fitness = result.fitness;
    motion.rmse = result.inlier_rms_m;
    motion.iterations = result.iterations;
    motion.inliers = static_cast<int32_t>(result.inliers);
    motion.seconds = result.seconds;
    bus.Publish(channels::kLidarMotion, motion);
    published_[station.id].push_back(motion);
    result.converged ? ++motions_ : ++failures_;
  }
  previous_.emplace_back(station.id, std::move(cloud));
  while (static_cast<int>(previous_.size()) > settings_.previous_stations) previous_.pop_front();
  state_ = "waiting";
}

StageStatus LidarIcpNode::Status() const {
  StageStatus s;
  s.state = state_;
  s.counters = {{"stations", stations_}, {"motions", motions_}, {"failures", failures_}, {"busy_s", busy_s_}};
  return s;
}

}  // namespace fusecal
