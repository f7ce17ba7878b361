#include "handeye/node/handeye_node.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "foundation/observed_covariance.hpp"
#include "handeye/motion_selection.hpp"
#include "handeye/node/result_conversion.hpp"
#include "runtime/channels.hpp"
#include "formats/conversions.hpp"
#include "formats/extrinsic_status.hpp"

namespace fusecal {

namespace {

bool Positive(double v) { return std::isfinite(v) && v > 0; }
bool NonNegative(double v) { return std::isfinite(v) && v >= 0; }

bool Observable(const HandEyeResult& r) { return r.observability == Observability::kOk; }

// The alternation can start when the rotation is known: the scaleless translation may still be partly
// unobservable (every motion's unknown scale absorbs one direction; rotations about a pivot give
// translation directions that repeat), which the metric camera motions of fusion odometry resolve.
bool CanRefine(const HandEyeResult& r) {
  return r.usable() && r.observability != Observability::kRotationDegenerate &&
         r.observability != Observability::kTooFewMotions;
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

std::string HandEyeNodeSettings::Validate() const {
  if (!Positive(tolerance_rotation_deg)) return "tolerance_rotation_deg: must be positive";
  if (!Positive(tolerance_translation_m)) return "tolerance_translation_m: must be positive";
  if (max_iterations < 1 || max_iterations > 1000) return "max_iterations: must be in [1, 1000]";
  if (!NonNegative(tolerance_std_fraction) || tolerance_std_fraction > 1) return "tolerance_std_fraction: must be in [0, 1]";
  if (!NonNegative(retry_s)) return "retry_s: must not be negative";
  if (max_motions < std::max(2, solver.min_pairs) || max_motions > 100000)
    return "max_motions: must be in [min_pairs, 100000] (min_pairs is " + std::to_string(solver.min_pairs) + ")";
  const std::string solver_problem = solver.Validate();
  return solver_problem.empty() ? solver_problem : "solver." + solver_problem;
}

namespace {
void ReadSharedErrors(ConfigReader r, SharedErrors* e) {
  r.Get("rotation_per_rotation", &e->rotation_per_rotation, ::fusecal::NonNegative<double>());
  r.Get("translation_per_translation", &e->translation_per_translation, ::fusecal::NonNegative<double>());
  r.Get("translation_per_rotation_m", &e->translation_per_rotation_m, ::fusecal::NonNegative<double>());
  r.Get("translation_scale", &e->translation_scale, ::fusecal::NonNegative<double>());
  r.Finish();
}
}  // namespace

HandEyeNodeSettings ReadHandEyeNodeSettings(ConfigReader r) {
  HandEyeNodeSettings s;
  r.Get("tolerance_rotation_deg", &s.tolerance_rotation_deg);
  r.Get("tolerance_translation_m", &s.tolerance_translation_m);
  r.Get("tolerance_std_fraction", &s.tolerance_std_fraction);
  r.Get("max_iterations", &s.max_iterations);
  r.Get("retry_s", &s.retry_s);
  r.Get("scaled_refinement", &s.scaled_refinement);
  r.Get("max_motions", &s.max_motions);
  r.Get("max_angle_difference_deg", &s.solver.max_angle_difference_deg);
  r.Get("min_rotation_deg", &s.solver.min_rotation_deg);
  r.Get("min_pairs", &s.solver.min_pairs);
  ConfigReader shared = r.Child("shared_errors");
  ReadSharedErrors(shared.Child("camera"), &s.solver.shared_camera_errors);
  ReadSharedErrors(shared.Child("lidar"), &s.solver.shared_lidar_errors);
  shared.Finish();
  r.Finish();
  r.FailIfInvalid(s.Validate(), {{"max_angle_difference_deg", "solver.max_angle_difference_deg"},
                                 {"min_rotation_deg", "solver.min_rotation_deg"},
                                 {"min_pairs", "solver.min_pairs"}});
  return s;
}

void HandEyeNode::Start(Bus& bus) {
  const auto on_motion = [this, &bus](const motion_t& m) { OnMotion(bus, m); };
  subscriptions_.push_back(bus.Subscribe(typed_channels::kCameraMotion, on_motion));
  subscriptions_.push_back(bus.Subscribe(typed_channels::kLidarMotion, on_motion));
  subscriptions_.push_back(
      bus.Subscribe(typed_channels::kFusedMotions, [this, &bus](const motion_set_t& s) { OnFusedMotions(bus, s); }));
}

void HandEyeNode::OnMotion(Bus& bus, const motion_t& motion) {
  const PairKey key{motion.station_i, motion.station_j};
  if (dropped_.count(key)) return;  // a repeat (after a restart) of a pair dropped for good
  auto& store = motion.sensor == "camera" ? camera_motions_ : lidar_motions_;
  const bool known = store.count(key) > 0;
  store[key] = motion;
  if (known || !motion.valid) return;
  // A new usable pair completes a motion: start a new round of the alternation.
  const auto other = motion.sensor == "camera" ? lidar_motions_.find(key) : camera_motions_.find(key);
  const auto& others = motion.sensor == "camera" ? lidar_motions_ : camera_motions_;
  if (other == others.end() || !other->second.valid) return;
  LimitPairs();
  StartRound(bus);
}

void HandEyeNode::LimitPairs() {
  const std::vector<MotionPair> pairs = ScalelessPairs();
  if (static_cast<int>(pairs.size()) <= settings_.max_motions) return;
  const std::vector<int> keep =
      SelectInformativePairs(pairs, settings_.max_motions, settings_.solver.nominal_rotation_sigma_deg);
  std::set<int> kept(keep.begin(), keep.end());
  for (int k = 0; k < static_cast<int>(pairs.size()); ++k) {
    if (kept.count(k)) continue;
    const PairKey key{pairs[k].station_i, pairs[k].station_j};
    camera_motions_.erase(key);
    lidar_motions_.erase(key);
    dropped_.insert(key);
    dropped_since_publish_.push_back(key);
  }
}

void HandEyeNode::ListHeldPairs(extrinsic_t* msg) const {
  std::set<PairKey> listed;
  for (int k = 0; k < msg->num_used; ++k) listed.insert({msg->used_station_i[k], msg->used_station_j[k]});
  for (int k = 0; k < msg->num_rejected; ++k) listed.insert({msg->rejected_station_i[k], msg->rejected_station_j[k]});
  std::vector<PairKey> unlisted;
  for (const auto& p : ScalelessPairs()) unlisted.push_back({p.station_i, p.station_j});
  unlisted.insert(unlisted.end(), dropped_since_publish_.begin(), dropped_since_publish_.end());
  for (const auto& [i, j] : unlisted) {
    if (!listed.insert({i, j}).second) continue;
    msg->rejected_station_i.push_back(i);
    msg->rejected_station_j.push_back(j);
  }
  msg->num_rejected = static_cast<int32_t>(msg->rejected_station_i.size());
}

bool HandEyeNode::PairWithLidar(const motion_t& camera, MotionPair* pair) const {
  const auto lidar = lidar_motions_.find({camera.station_i, camera.station_j});
  if (!camera.valid || lidar == lidar_motions_.end() || !lidar->second.valid) return false;
  pair->station_i = camera.station_i;
  pair->station_j = camera.station_j;
  pair->A = FromRowMajor(camera.T_i_j);
  pair->B = FromRowMajor(lidar->second.T_i_j);
  pair->camera_scaled = camera.scaled;
  return true;
}

std::vector<MotionPair> HandEyeNode::ScalelessPairs() const {
  std::vector<MotionPair> pairs;
  MotionPair p;
  for (const auto& [key, camera] : camera_motions_)
    if (PairWithLidar(camera, &p)) pairs.push_back(p);
  return pairs;
}

void HandEyeNode::StartRound(Bus& bus) {
  const auto start = std::chrono::steady_clock::now();
  // No prior: the scaleless estimate stays what the scaleless motions alone say (the baseline).
  // The verdict keeps its hysteresis from the previous solve of the same kind.
  HandEyeSettings solver = settings_.solver;
  if (initial_ && initial_->usable()) solver.previous_verdict = initial_->observability;
  initial_ = SolveScaleless(ScalelessPairs(), solver);
  work_.Add(Seconds(start));
  iteration_ = 0;
  converged_ = false;
  const bool usable = CanRefine(*initial_);
  const bool resume = usable && current_ && current_->scaled;
  const bool ask = usable && settings_.scaled_refinement;
  if (!usable) {
    // Not enough to refine: report what the motions give and wait for more.
    const int8_t status = initial_->usable() ? extrinsic_t::STATUS_DEGENERATE : extrinsic_t::STATUS_FAILED;
    if (!current_ || !current_->scaled) current_ = *initial_;
    state_ = std::string("waiting for motions (") + Name(initial_->observability) + ")";
    Publish(bus, *initial_, status, {}, false);
    return;
  }
  if (!ask) {
    current_ = *initial_;
    converged_ = Observable(*initial_) && initial_->converged;
    state_ = converged_ ? "converged (scaleless)"
                        : std::string("waiting for motions (") + Name(initial_->observability) + ")";
    Publish(bus, *initial_, converged_ ? extrinsic_t::STATUS_CONVERGED : extrinsic_t::STATUS_DEGENERATE, {}, false);
    return;
  }
  state_ = "refining";
  if (resume) {
    // The scaleless estimate over all motions, for the record; then continue from the scaled estimate.
    Publish(bus, *initial_, extrinsic_t::STATUS_INITIAL, {}, false);
    Publish(bus, *current_, extrinsic_t::STATUS_REFINING, {}, true);
  } else {
    current_ = *initial_;
    Publish(bus, *initial_, extrinsic_t::STATUS_REFINING, {}, true);
  }
}

void HandEyeNode::OnFusedMotions(Bus& bus, const motion_set_t& set) {
  if (set.extrinsic_version != awaiting_version_) return;  // old or repeated answer
  const auto start = std::chrono::steady_clock::now();
  std::vector<MotionPair> pairs;
  std::string first_failure;
  int failed = 0;
  for (const auto& m : set.motions) {
    if (!m.valid && failed++ == 0)
      first_failure = std::to_string(m.station_i) + "-" + std::to_string(m.station_j) + ": " + m.failure_reason;
    MotionPair p;
    if (m.scaled && PairWithLidar(m, &p)) pairs.push_back(p);
  }
  HandEyeSettings solver = settings_.solver;
  if (current_->scaled && current_->usable()) solver.previous_verdict = current_->observability;
  HandEyeResult result = SolveScaled(pairs, solver, &current_->T_camera_lidar);
  work_.Add(Seconds(start));
  if (!result.usable()) {
    // Keep what we had; say why and wait for more motions.
    awaiting_version_ = -1;
    std::string why = "scaled solve failed: " + result.message;
    if (failed > 0)
      why = "fusion odometry failed for " + std::to_string(failed) + " of " + std::to_string(set.motions.size()) +
            " motions (first: " + first_failure + "); " + why;
    state_ = "waiting for motions (" + why + ")";
    HandEyeResult kept = *current_;
    kept.message = why;
    Publish(bus, kept, extrinsic_t::STATUS_FAILED, {}, false);
    return;
  }
  const double change_rot_deg = RotationErrorDeg(result.T_camera_lidar.linear(), current_->T_camera_lidar.linear());
  const Change change{change_rot_deg * M_PI / 180.0,
                      (result.T_camera_lidar.translation() - current_->T_camera_lidar.translation()).norm()};
  current_ = result;
  ++iteration_;
  const ObservedUncertainty observed =
      ObservedPart(result.covariance, result.T_camera_lidar.linear(), result.unobservable_direction);
  const double f = settings_.tolerance_std_fraction;
  const bool small = change_rot_deg < std::max(settings_.tolerance_rotation_deg, f * observed.max_rotation_std_deg) &&
                     change.translation_m < std::max(settings_.tolerance_translation_m, f * observed.max_translation_std_m);
  const bool done = small || iteration_ >= settings_.max_iterations;
  int8_t status = extrinsic_t::STATUS_REFINING;
  if (done)
    status = !Observable(result)                 ? extrinsic_t::STATUS_DEGENERATE
             : result.converged && small         ? extrinsic_t::STATUS_CONVERGED
                                                 : extrinsic_t::STATUS_NOT_CONVERGED;
  converged_ = status == extrinsic_t::STATUS_CONVERGED;
  state_ = ExtrinsicStatusName(status);
  Publish(bus, result, status, change, !done);
}

void HandEyeNode::Publish(Bus& bus, const HandEyeResult& result, int8_t status, Change change, bool ask) {
  extrinsic_t msg = ToExtrinsicMessage(result, ++version_, NowUtime());
  if (ask && initial_) {
    // Fusion odometry computes the pairs a request lists: all that the newest scaleless solve used.
    const extrinsic_t pairs = ToExtrinsicMessage(*initial_, 0, 0);
    msg.num_used = pairs.num_used;
    msg.used_station_i = pairs.used_station_i;
    msg.used_station_j = pairs.used_station_j;
  }
  // Pairs that this solve did not take (too few motions, not asked for, rejected before) are listed as not
  // used: stations of the held pairs are kept by fusion odometry and the coordinator by this list.
  ListHeldPairs(&msg);
  dropped_since_publish_.clear();
  msg.status = status;
  msg.converged = status == extrinsic_t::STATUS_CONVERGED;
  msg.iteration = iteration_;
  msg.change_rotation_rad = change.rotation_rad;
  msg.change_translation_m = change.translation_m;
  last_published_ = msg;
  last_sent_utime_ = NowUtime();
  awaiting_version_ = ask ? version_ : -1;
  bus.Publish(channels::kExtrinsic, msg);
}

void HandEyeNode::Tick(Bus& bus, int64_t now_utime) {
  if (awaiting_version_ < 0 || settings_.retry_s <= 0) return;
  if (now_utime - last_sent_utime_ < static_cast<int64_t>(settings_.retry_s * 1e6)) return;
  ++retries_;
  last_sent_utime_ = now_utime;
  bus.Publish(channels::kExtrinsic, last_published_);  // same version: answered from cache if seen
}

StageStatus HandEyeNode::Status() const {
  StageStatus s;
  s.state = state_;
  s.counters = {{"camera_motions", double(camera_motions_.size())},
                {"lidar_motions", double(lidar_motions_.size())},
                {"pairs", double(ScalelessPairs().size())},
                {"version", version_},
                {"iteration", iteration_},
                {"retries", retries_},
                {"dropped_motions", double(dropped_.size())}};
  work_.AddTo(&s.counters);  // items: solves
  return s;
}

}  // namespace fusecal
