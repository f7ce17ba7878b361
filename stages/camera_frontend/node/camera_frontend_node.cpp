#include "camera_frontend/node/camera_frontend_node.hpp"

#include <chrono>

#include "runtime/channels.hpp"
#include "runtime/conversions.hpp"
#include "runtime/motion_message.hpp"

namespace fusecal {

CameraFrontendNodeSettings ReadCameraFrontendNodeSettings(ConfigReader r) {
  CameraFrontendNodeSettings s;
  r.Get("previous_stations", &s.previous_stations, InRange(1, 10));
  r.Get("max_features", &s.frontend.features.max_features, Positive<int>());
  r.Get("ratio", &s.frontend.matching.ratio, InRange(0.1, 1.0));
  r.Get("min_inliers", &s.frontend.min_inliers, Positive<int>());
  r.Finish();
  const std::string error = s.frontend.Validate();
  if (!error.empty()) r.FailSection(error);
  return s;
}

void CameraFrontendNode::Start(Bus& bus) {
  subscriptions_.push_back(bus.Subscribe<station_t>(
      channels::kStation, std::function<void(const station_t&)>([this, &bus](const station_t& s) { OnStation(bus, s); })));
}

void CameraFrontendNode::OnStation(Bus& bus, const station_t& station) {
  if (const auto seen = published_.find(station.id); seen != published_.end()) {
    for (const auto& motion : seen->second) bus.Publish(channels::kCameraMotion, motion);
    return;
  }
  published_[station.id];
  ++stations_;
  const auto start = std::chrono::steady_clock::now();
  cv::Mat image;
  try {
    camera_ = MakeCameraModel(CameraFromMsg(station.camera));
    image = ImageToMat(station.image);
  } catch (const std::exception& e) {
    ++failures_;
    previous_.clear();  // the next station has nothing valid to pair with
    throw std::runtime_error("station " + std::to_string(station.id) + ": " + e.what());
  }
  ImageFeatures features = ExtractImageFeatures(image, *camera_, settings_.frontend.features);
  for (const auto& [previous_id, previous_features] : previous_) {
    const RelativePoseResult result = EstimateRelativePose(previous_features, features, *camera_, settings_.frontend);
    motion_t motion;
    if (result.motion_valid()) {
      motion = MakeMotion(previous_id, station.id, "camera", result.A(), false, result.covariance, station.utime);
      ++motions_;
    } else {
      motion = MakeFailedMotion(previous_id, station.id, "camera", result.failure_reason, station.utime);
      ++failures_;
    }
    motion.inliers = result.inliers;
    motion.rmse = result.median_epipolar_error_deg;
    motion.iterations = result.refinement_iterations;
    motion.seconds = result.seconds;
    bus.Publish(channels::kCameraMotion, motion);
    published_[station.id].push_back(motion);
  }
  previous_.emplace_back(station.id, std::move(features));
  while (static_cast<int>(previous_.size()) > settings_.previous_stations) previous_.pop_front();
  busy_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

StageStatus CameraFrontendNode::Status() const {
  StageStatus s;
  s.counters = {{"stations", stations_}, {"motions", motions_}, {"failures", failures_}, {"busy_s", busy_s_}};
  return s;
}

}  // namespace fusecal
