#include "stages/fusion_odometry/node/fusion_odometry_node.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/core/utility.hpp>

#include "fusecal/motion_t.hpp"
#include "runtime/channels.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/motion_message.hpp"

namespace fusecal {

namespace {
bool NonNegative(double v) { return std::isfinite(v) && v >= 0; }

// The largest std of a 3x3 block of the extrinsic's covariance (row-major 6x6, rotation first); nan
// when the block is not a covariance.
double LargestStd(const double* covariance, int first) {
  Eigen::Matrix3d block;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) block(r, c) = covariance[(first + r) * 6 + first + c];
  if (!block.allFinite()) return std::nan("");
  const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(block).eigenvalues().maxCoeff();
  return largest >= 0 ? std::sqrt(largest) : std::nan("");
}
}  // namespace

std::string FusionOdometryNodeSettings::Validate() const {
  if (!NonNegative(input_wait_s)) return "input_wait_s: must not be negative";
  if (!NonNegative(reuse_rotation_deg)) return "reuse_rotation_deg: must not be negative";
  if (!NonNegative(reuse_translation_m)) return "reuse_translation_m: must not be negative";
  if (!NonNegative(reuse_std_fraction) || reuse_std_fraction > 1) return "reuse_std_fraction: must be in [0, 1]";
  return odometry.Validate();
}

FusionOdometryNodeSettings ReadFusionOdometryNodeSettings(ConfigReader r) {
  FusionOdometryNodeSettings s;
  r.Get("input_wait_s", &s.input_wait_s);
  r.Get("reuse_rotation_deg", &s.reuse_rotation_deg);
  r.Get("reuse_translation_m", &s.reuse_translation_m);
  r.Get("reuse_std_fraction", &s.reuse_std_fraction);
  r.Finish();
  r.FailIfInvalid(s.Validate());
  return s;
}

void FusionOdometryNode::Start(Bus& bus) {
  subscriptions_.push_back(
      bus.Subscribe(ForCamera(channels::kStation, settings_.camera), [this, &bus](const station_t& s) {
        OnStation(s);
        AnswerPendingIfReady(bus, false);
      }));
  subscriptions_.push_back(bus.Subscribe(channels::kLidarMotion, [this, &bus](const motion_t& m) {
    if (m.valid) lidar_motions_[{m.station_i, m.station_j}] = FromRowMajor(m.T_i_j);
    AnswerPendingIfReady(bus, false);
  }));
  subscriptions_.push_back(bus.Subscribe(ForCamera(channels::kExtrinsic, settings_.camera),
                                         [this, &bus](const extrinsic_t& e) { OnExtrinsic(bus, e); }));
}

void FusionOdometryNode::OnStation(const station_t& station) {
  CachedStation cached;
  cached.image = ImageToMat(station.image);
  cached.cloud = CloudFromMsg(station.cloud);
  cached.camera = MakeCameraModel(CameraFromMsg(station.camera));
  stations_[station.id] = std::move(cached);
  retention_.OnStation(station.id);
  EvictStations();
}

void FusionOdometryNode::EvictStations() {
  const int dropped = retention_.Evict(&stations_);
  if (dropped == 0) return;
  stations_dropped_ += dropped;
  const auto gone = [this](const PairKey& pair) {
    return !retention_.Keep(pair.first) || !retention_.Keep(pair.second);
  };
  const auto erase_pairs = [&gone](auto* map) {
    for (auto it = map->begin(); it != map->end();) it = gone(it->first) ? map->erase(it) : std::next(it);
  };
  erase_pairs(&lidar_motions_);
  erase_pairs(&last_camera_motions_);
  erase_pairs(&last_computed_);
}

motion_t FusionOdometryNode::ComputeMotion(int i, int j, const Isometry3& X, int version,
                                           fusion_odometry::FusionOdometryResult* result) const {
  const int64_t now = NowUtime();
  const auto si = stations_.find(i), sj = stations_.find(j);
  if (si == stations_.end() || sj == stations_.end())
    return MakeFailedMotion(i, j, "camera",
                            "station " + std::to_string(si == stations_.end() ? i : j) + " not received", now);
  fusion_odometry::MotionGuess guess;
  const auto warm = last_camera_motions_.find({i, j});
  const auto lidar = lidar_motions_.find({i, j});
  if (warm != last_camera_motions_.end()) {
    guess.T_ci_cj = warm->second;
    guess.reliable = true;
  } else if (lidar != lidar_motions_.end()) {
    guess.T_ci_cj = fusion_odometry::CameraMotionFromLidar(X, lidar->second);
  }
  *result = fusion_odometry::EstimateScaledMotion(si->second.cloud, si->second.image, sj->second.image,
                                                  *si->second.camera, X, guess, settings_.odometry);
  motion_t m = result->usable() ? MakeMotion(i, j, "camera", result->T_ci_cj, true, result->covariance, now)
                                : MakeFailedMotion(i, j, "camera", result->failure_reason.text, now);
  m.inliers = result->inliers;
  m.rmse = result->rms_residual_px;
  m.iterations = result->refinement_iterations;
  m.seconds = result->seconds;
  m.extrinsic_version = version;
  return m;
}

// An extrinsic within
// its std of the one a motion was computed with is the same extrinsic as far as the motions can tell:
// recomputing the motion draws its noise again (which tracks see which points) and adds no information,
// while an error delta in X moves a fused motion by about delta times the motion's angle and the
// estimate by less (the alternation contracts: docs/design.md section 4). Without this, each new
// station in a long session made every held pair computed again, about max_motions of them per station,
// more than two cores keep pace with.
ReuseTolerance FusedMotionReuseTolerance(const FusionOdometryNodeSettings& settings, const extrinsic_t& e) {
  ReuseTolerance tolerance{settings.reuse_rotation_deg, settings.reuse_translation_m};
  if (settings.reuse_std_fraction <= 0 || e.observability != extrinsic_t::OBSERVABILITY_OK) return tolerance;
  const double rotation_std_deg = LargestStd(e.covariance, 0) * 180.0 / M_PI;
  const double translation_std_m = LargestStd(e.covariance, 3);
  if (std::isfinite(rotation_std_deg) && std::isfinite(translation_std_m)) {
    tolerance.rotation_deg = std::max(tolerance.rotation_deg, settings.reuse_std_fraction * rotation_std_deg);
    tolerance.translation_m = std::max(tolerance.translation_m, settings.reuse_std_fraction * translation_std_m);
  }
  return tolerance;
}

bool FusionOdometryNode::Reusable(const PairKey& pair, const Isometry3& X, const ReuseTolerance& tolerance) const {
  const auto last = last_computed_.find(pair);
  if (last == last_computed_.end()) return false;
  return RotationErrorDeg(X.linear(), last->second.X.linear()) < tolerance.rotation_deg &&
         (X.translation() - last->second.X.translation()).norm() < tolerance.translation_m;
}

// The motions of one round are independent (each reads the stations, the LiDAR motions and its own warm
// start): they are computed in parallel on both cores, then recorded in the order of the request, so the
// answer is the same as computed one after the other.
std::vector<motion_t> FusionOdometryNode::ComputeMotions(const extrinsic_t& extrinsic) {
  const Isometry3 X = FromRowMajor(extrinsic.T_camera_lidar);
  const ReuseTolerance tolerance = FusedMotionReuseTolerance(settings_, extrinsic);
  std::vector<motion_t> motions(extrinsic.num_used);
  std::vector<int> to_compute;  // indices into the request
  for (int k = 0; k < extrinsic.num_used; ++k) {
    const PairKey pair{extrinsic.used_station_i[k], extrinsic.used_station_j[k]};
    if (Reusable(pair, X, tolerance)) {
      motions[k] = last_computed_.at(pair).motion;
      motions[k].extrinsic_version = extrinsic.version;
      ++reused_;
    } else {
      to_compute.push_back(k);
    }
  }
  const int n = static_cast<int>(to_compute.size());
  std::vector<fusion_odometry::FusionOdometryResult> results(n);
  // OpenCV's own threads inside each motion would compete with these (measured: a round took longer in
  // parallel than one after the other); one motion per core instead.
  const int opencv_threads = cv::getNumThreads();
  if (n > 1) cv::setNumThreads(1);
#pragma omp parallel for schedule(dynamic, 1) if (n > 1)
  for (int c = 0; c < n; ++c) {
    const int k = to_compute[c];
    motions[k] =
        ComputeMotion(extrinsic.used_station_i[k], extrinsic.used_station_j[k], X, extrinsic.version, &results[c]);
  }
  if (n > 1) cv::setNumThreads(opencv_threads);
  for (int c = 0; c < n; ++c) {
    const motion_t& m = motions[to_compute[c]];
    work_.Add(results[c].seconds);
    last_computed_[{m.station_i, m.station_j}] = {X, m};
    if (results[c].usable()) {
      last_camera_motions_[{m.station_i, m.station_j}] = results[c].T_ci_cj;
      ++motions_;
    } else {
      ++failures_;
    }
  }
  return motions;
}

void FusionOdometryNode::OnExtrinsic(Bus& bus, const extrinsic_t& extrinsic) {
  retention_.OnExtrinsic(extrinsic);
  EvictStations();
  if (const auto cached = answered_.find(extrinsic.version); cached != answered_.end()) {
    ++repeats_;
    bus.Publish(ForCamera(channels::kFusedMotions, settings_.camera), cached->second);
    return;
  }
  // Only versions that ask for refinement are answered.
  if (extrinsic.version <= newest_answered_ || extrinsic.status != extrinsic_t::STATUS_REFINING) return;
  pending_ = extrinsic;
  pending_since_utime_ = NowUtime();
  AnswerPendingIfReady(bus, settings_.input_wait_s <= 0);
}

// Channels are not ordered with respect to each other (DDS has a reader per topic): a request may come
// before the stations or the LiDAR motions it needs, and the LiDAR motion is the first guess of a pair.
// The answer waits for them (at most input_wait_s, then goes ahead), so that it does not depend on the
// order of arrival and `run` computes what `calibrate` computes. (In-process, over memq, the order is
// the order of publication: `calibrate` sets input_wait_s to 0.)
bool FusionOdometryNode::HasInputsFor(const extrinsic_t& e) const {
  for (int k = 0; k < e.num_used; ++k) {
    const PairKey key{e.used_station_i[k], e.used_station_j[k]};
    if (!stations_.count(key.first) || !stations_.count(key.second)) return false;
    if (!last_camera_motions_.count(key) && !lidar_motions_.count(key)) return false;
  }
  return true;
}

void FusionOdometryNode::AnswerPendingIfReady(Bus& bus, bool waited_enough) {
  if (!pending_ || pending_->version <= newest_answered_) return;
  if (!HasInputsFor(*pending_)) {
    if (!waited_enough) return;
    ++answered_without_inputs_;
  }
  const extrinsic_t extrinsic = *pending_;
  pending_.reset();
  motion_set_t answer{};
  answer.motions = ComputeMotions(extrinsic);
  answer.utime = NowUtime();
  answer.extrinsic_version = extrinsic.version;
  answer.num_motions = static_cast<int32_t>(answer.motions.size());
  newest_answered_ = extrinsic.version;
  answered_[extrinsic.version] = answer;
  while (answered_.size() > 4) answered_.erase(answered_.begin());
  bus.Publish(ForCamera(channels::kFusedMotions, settings_.camera), answer);
}

void FusionOdometryNode::Tick(Bus& bus, int64_t now_utime) {
  if (pending_ && now_utime - pending_since_utime_ > settings_.input_wait_s * 1e6) AnswerPendingIfReady(bus, true);
}

StageStatus FusionOdometryNode::Status() const {
  StageStatus s;
  s.counters = {{"stations", double(stations_.size())},
                {"motions", motions_},
                {"failures", failures_},
                {"repeats", repeats_},
                {"version", newest_answered_},
                {"answered_without_inputs", answered_without_inputs_},
                {"reused", double(reused_)},
                {"stations_dropped", double(stations_dropped_)}};
  work_.AddTo(&s.counters);  // items: motions computed (one per pair and iteration)
  return s;
}

}  // namespace fusecal
