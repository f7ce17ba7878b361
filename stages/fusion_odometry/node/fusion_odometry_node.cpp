#include "fusion_odometry/node/fusion_odometry_node.hpp"

#include <chrono>

#include "fusecal/motion_t.hpp"
#include "runtime/channels.hpp"
#include "formats/conversions.hpp"
#include "formats/motion_message.hpp"

namespace fusecal {

FusionOdometryNodeSettings ReadFusionOdometryNodeSettings(ConfigReader r) {
  FusionOdometryNodeSettings s;
  r.Finish();
  const std::string error = s.odometry.Validate();
  if (!error.empty()) r.FailSection(error);
  return s;
}

void FusionOdometryNode::Start(Bus& bus) {
  subscriptions_.push_back(bus.Subscribe<station_t>(
      channels::kStation, std::function<void(const station_t&)>([this](const station_t& s) { OnStation(s); })));
  subscriptions_.push_back(bus.Subscribe<motion_t>(
      channels::kLidarMotion, std::function<void(const motion_t&)>([this](const motion_t& m) {
        if (m.valid) lidar_motions_[{m.station_i, m.station_j}] = FromRowMajor(m.T_i_j);
      })));
  subscriptions_.push_back(bus.Subscribe<extrinsic_t>(
      channels::kExtrinsic,
      std::function<void(const extrinsic_t&)>([this, &bus](const extrinsic_t& e) { OnExtrinsic(bus, e); })));
}

void FusionOdometryNode::OnStation(const station_t& station) {
  CachedStation cached;
  cached.image = ImageToMat(station.image);
  cached.cloud = CloudFromMsg(station.cloud);
  cached.camera = MakeCameraModel(CameraFromMsg(station.camera));
  stations_[station.id] = std::move(cached);
}

motion_t FusionOdometryNode::ComputeMotion(int i, int j, const Isometry3& X, int version) {
  const int64_t now = NowUtime();
  const auto si = stations_.find(i), sj = stations_.find(j);
  if (si == stations_.end() || sj == stations_.end())
    return MakeFailedMotion(i, j, "camera", "station " + std::to_string(si == stations_.end() ? i : j) + " not received",
                            now);
  fusion_odometry::MotionGuess guess;
  const auto warm = last_camera_motions_.find({i, j});
  const auto lidar = lidar_motions_.find({i, j});
  if (warm != last_camera_motions_.end()) {
    guess.T_ci_cj = warm->second;
    guess.reliable = true;
  } else if (lidar != lidar_motions_.end()) {
    guess.T_ci_cj = fusion_odometry::CameraMotionFromLidar(X, lidar->second);
  }
  const auto result = fusion_odometry::EstimateScaledMotion(si->second.cloud, si->second.image, sj->second.image,
                                                            *si->second.camera, X, guess, settings_.odometry);
  busy_s_ += result.seconds;
  motion_t m = result.converged
                   ? MakeMotion(i, j, "camera", result.T_ci_cj, true, result.covariance, now)
                   : MakeFailedMotion(i, j, "camera", result.failure_reason, now);
  m.inliers = result.inliers;
  m.rmse = result.rms_residual_px;
  m.iterations = result.refinement_iterations;
  m.seconds = result.seconds;
  m.extrinsic_version = version;
  if (result.converged) {
    last_camera_motions_[{i, j}] = result.T_ci_cj;
    ++motions_;
  } else {
    ++failures_;
  }
  return m;
}

void FusionOdometryNode::OnExtrinsic(Bus& bus, const extrinsic_t& extrinsic) {
  if (const auto cached = answered_.find(extrinsic.version); cached != answered_.end()) {
    ++repeats_;
    bus.Publish(channels::kFusedMotions, cached->second);
    return;
  }
  // Only versions that ask for refinement are answered.
  if (extrinsic.version <= newest_answered_ || extrinsic.status != extrinsic_t::STATUS_REFINING) return;
  const Isometry3 X = FromRowMajor(extrinsic.T_camera_lidar);
  motion_set_t answer{};
  answer.utime = NowUtime();
  answer.extrinsic_version = extrinsic.version;
  for (int k = 0; k < extrinsic.num_used; ++k)
    answer.motions.push_back(ComputeMotion(extrinsic.used_station_i[k], extrinsic.used_station_j[k], X, extrinsic.version));
  answer.num_motions = static_cast<int32_t>(answer.motions.size());
  newest_answered_ = extrinsic.version;
  answered_[extrinsic.version] = answer;
  while (answered_.size() > 4) answered_.erase(answered_.begin());
  bus.Publish(channels::kFusedMotions, answer);
}

StageStatus FusionOdometryNode::Status() const {
  StageStatus s;
  s.counters = {{"stations", double(stations_.size())}, {"motions", motions_}, {"failures", failures_},
                {"repeats", repeats_},                  {"version", newest_answered_}, {"busy_s", busy_s_}};
  return s;
}

}  // namespace fusecal
