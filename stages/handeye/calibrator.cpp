#include "stages/handeye/calibrator.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "stages/foundation/observed_covariance.hpp"
#include "stages/handeye/motion_selection.hpp"
#include "stages/handeye/split_test.hpp"

namespace fusecal {

namespace {

bool Positive(double v) { return std::isfinite(v) && v > 0; }

// Pairs in the order their motions end (station_j, then station_i).
void SortByArrival(std::vector<MotionPair>* pairs) {
  std::sort(pairs->begin(), pairs->end(), [](const MotionPair& a, const MotionPair& b) {
    return std::make_pair(a.station_j, a.station_i) < std::make_pair(b.station_j, b.station_i);
  });
}
bool NonNegative(double v) { return std::isfinite(v) && v >= 0; }

bool Observable(const HandEyeResult& r) { return r.observability == Observability::kOk; }

// The alternation can start when the rotation is known: the scaleless translation may still be partly
// unobservable (every motion's unknown scale absorbs one direction; rotations about a pivot give
// translation directions that repeat), which the metric camera motions of fusion odometry resolve.
bool CanRefine(const HandEyeResult& r) {
  return r.usable() && r.observability != Observability::kRotationDegenerate &&
         r.observability != Observability::kTooFewMotions;
}

StationPair KeyOf(const SensorMotion& m) { return {m.station_i, m.station_j}; }

}  // namespace

Calibrator::Change Calibrator::Difference(const Isometry3& a, const Isometry3& b) {
  return {RotationErrorDeg(a.linear(), b.linear()) * M_PI / 180.0, (a.translation() - b.translation()).norm()};
}

const char* Name(VersionStatus status) {
  switch (status) {
    case VersionStatus::kInitial:
      return "initial";
    case VersionStatus::kRefining:
      return "refining";
    case VersionStatus::kConverged:
      return "converged";
    case VersionStatus::kNotConverged:
      return "not_converged";
    case VersionStatus::kDegenerate:
      return "degenerate";
    case VersionStatus::kFailed:
      return "failed";
  }
  return "unknown";
}

std::string CalibratorSettings::Validate() const {
  if (!Positive(tolerance_rotation_deg)) return "tolerance_rotation_deg: must be positive";
  if (!Positive(tolerance_translation_m)) return "tolerance_translation_m: must be positive";
  if (max_iterations < 1 || max_iterations > 1000) return "max_iterations: must be in [1, 1000]";
  if (!NonNegative(tolerance_std_fraction) || tolerance_std_fraction > 1)
    return "tolerance_std_fraction: must be in [0, 1]";
  if (!NonNegative(retry_s)) return "retry_s: must not be negative";
  if (max_motions < std::max(2, solver.min_pairs) || max_motions > 100000)
    return "max_motions: must be in [min_pairs, 100000] (min_pairs is " + std::to_string(solver.min_pairs) + ")";
  const std::string change_problem = change_detection.Validate();
  if (!change_problem.empty()) return "change_detection." + change_problem;
  const std::string solver_problem = solver.Validate();
  return solver_problem.empty() ? solver_problem : "solver." + solver_problem;
}

std::vector<CalibrationVersion> Calibrator::OnMotion(const SensorMotion& motion, int64_t now_utime) {
  const StationPair key = KeyOf(motion);
  if (dropped_.count(key)) return {};  // a repeat (after a restart) of a pair dropped for good
  if (segment_after_ && motion.station_i <= *segment_after_) {
    Drop(key);  // late news from before a change
    return {};
  }
  const bool camera = motion.sensor == SensorMotion::Sensor::kCamera;
  auto& store = camera ? camera_motions_ : lidar_motions_;
  const bool known = store.count(key) > 0;
  store[key] = motion;
  if (known || !motion.valid) return {};
  // A new usable pair completes a motion: start a new round of the alternation.
  const auto& others = camera ? lidar_motions_ : camera_motions_;
  const auto other = others.find(key);
  if (other == others.end() || !other->second.valid) return {};
  LimitPairs();
  // The new pair's rotation is tested as it comes (also when the solve will reject it as an outlier).
  if (const auto change = DetectChange(ScalelessPairs()))
    return StartAfterChange(change->first, change->second, *reference_, now_utime);
  return StartRound(now_utime);
}

std::optional<StationPair> Calibrator::DetectChange(std::vector<MotionPair> pairs) {
  SortByArrival(&pairs);
  for (const MotionPair& p : pairs) {
    auto& tested = p.camera_scaled ? tested_metric_ : tested_scaleless_;
    if (!tested.insert({p.station_i, p.station_j}).second) continue;
    // The reference: a scaled estimate from before these pairs (or, without fusion odometry, the scaleless
    // one), kept from before the first off pair while the newest pairs hold one. While the scaled estimate is
    // rotation-degenerate (the first motions all turned about one axis), it is the scaleless one: fusion
    // odometry's motions at an extrinsic off along the unobservable direction miss by far more than their
    // noise (0.13 deg against 0.005 in simulation), and that noise would hide any change; the 5-point
    // rotations do not depend on the extrinsic. Metric motions are then not tested one by one; once the estimate is
    // observable, the change-point test takes them (DetectChangeBySplit).
    if (!detector_.Suspicious()) {
      if (const HandEyeResult* reference = Reference()) reference_ = *reference;
    }
    if (!reference_) continue;
    if (p.camera_scaled && !reference_->scaled && settings_.scaled_refinement) {
      untested_metric_.insert({p.station_i, p.station_j});
      continue;
    }
    const PairTest test = TestPair(p, *reference_, settings_.solver, settings_.change_detection);
    if (const auto after = detector_.Add(test)) return StationPair{*after, p.station_j};
  }
  return std::nullopt;
}

std::optional<StationPair> Calibrator::DetectChangeBySplit(std::vector<MotionPair> pairs, HandEyeResult* before) {
  const ChangeDetectionSettings& cd = settings_.change_detection;
  // The metric motions were computed at the current estimate: off along an unobservable direction, they miss
  // by far more than their noise (DetectChange), so they are compared only once it is observable.
  if (!cd.enabled || untested_metric_.empty() || !current_ || !Observable(*current_)) return std::nullopt;
  SortByArrival(&pairs);
  const int n = static_cast<int>(pairs.size());
  std::vector<int> candidates;
  for (int k = 0; k < n; ++k) {
    const StationPair key{pairs[k].station_i, pairs[k].station_j};
    if (!untested_metric_.count(key)) continue;
    candidates.push_back(k);
    // As long as the pair-by-pair rule looks at a pair: while fewer than `window` pairs follow it.
    if (n - 1 - k >= cd.window) untested_metric_.erase(key);
  }
  const SplitTest split = TestSplits(pairs, candidates, current_->T_camera_lidar, settings_.solver,
                                     cd.confirm_probability, cd.split_min_noise_dof);
  if (!split.change) return std::nullopt;
  const std::vector<MotionPair> earlier(pairs.begin(), pairs.begin() + split.across);
  *before = SolveScaled(earlier, settings_.solver, &current_->T_camera_lidar);
  if (!before->usable()) *before = *current_;
  return StationPair{pairs[split.across].station_i, pairs.back().station_j};
}

const HandEyeResult* Calibrator::Reference() const {
  if (!settings_.scaled_refinement) return current_ && current_->usable() ? &*current_ : nullptr;
  const bool scaled = current_ && current_->usable() && current_->scaled;
  // Rotation-degenerate by its motions, not by their number: a scaleless estimate of two pairs, tested with
  // the 5-point rotations of a narrow field of view, reported changes in 2 of 50 unchanged sessions.
  const HandEyeResult* verdict = scaled ? &*current_ : initial_ ? &*initial_ : nullptr;
  const bool one_axis = verdict && verdict->observability == Observability::kRotationDegenerate;
  if (one_axis && initial_ && initial_->usable() && initial_->observability != Observability::kTooFewMotions)
    return &*initial_;
  return scaled ? &*current_ : nullptr;
}

void Calibrator::Drop(const StationPair& key) {
  camera_motions_.erase(key);
  lidar_motions_.erase(key);
  if (dropped_.insert(key).second) dropped_since_version_.push_back(key);
}

std::vector<CalibrationVersion> Calibrator::StartAfterChange(int after_station, int decided_at_station,
                                                             const HandEyeResult& before, int64_t now_utime) {
  changes_.push_back({after_station, decided_at_station, before.T_camera_lidar, before.covariance});
  segment_after_ = after_station;
  std::set<StationPair> past;
  for (const auto* store : {&camera_motions_, &lidar_motions_})
    for (const auto& [key, motion] : *store)
      if (key.first <= after_station) past.insert(key);
  for (const StationPair& key : past) Drop(key);
  current_.reset();
  initial_.reset();
  reference_.reset();
  detector_.Reset();
  untested_metric_.clear();
  note_ = "extrinsic changed after station " + std::to_string(after_station) + " (decided at station " +
          std::to_string(decided_at_station) + "); solving again from the motions after it";
  return StartRound(now_utime);
}

void Calibrator::LimitPairs() {
  const std::vector<MotionPair> pairs = ScalelessPairs();
  if (static_cast<int>(pairs.size()) <= settings_.max_motions) return;
  const std::vector<int> keep =
      SelectInformativePairs(pairs, settings_.max_motions, settings_.solver.nominal_rotation_sigma_deg);
  const std::set<int> kept(keep.begin(), keep.end());
  for (int k = 0; k < static_cast<int>(pairs.size()); ++k) {
    if (!kept.count(k)) Drop({pairs[k].station_i, pairs[k].station_j});
  }
}

bool Calibrator::PairWithLidar(const SensorMotion& camera, MotionPair* pair) const {
  const auto lidar = lidar_motions_.find(KeyOf(camera));
  if (!camera.valid || lidar == lidar_motions_.end() || !lidar->second.valid) return false;
  pair->station_i = camera.station_i;
  pair->station_j = camera.station_j;
  pair->A = camera.T_i_j;
  pair->B = lidar->second.T_i_j;
  pair->camera_scaled = camera.scaled;
  return true;
}

std::vector<MotionPair> Calibrator::ScalelessPairs() const {
  std::vector<MotionPair> pairs;
  MotionPair p;
  for (const auto& [key, camera] : camera_motions_)
    if (PairWithLidar(camera, &p)) pairs.push_back(p);
  return pairs;
}

std::vector<CalibrationVersion> Calibrator::StartRound(int64_t now_utime) {
  // No prior: the scaleless estimate stays what the scaleless motions alone say (the baseline).
  // The verdict keeps its hysteresis from the previous solve of the same kind.
  HandEyeSettings solver = settings_.solver;
  if (initial_ && initial_->usable()) solver.previous_verdict = initial_->observability;
  initial_ = SolveScaleless(ScalelessPairs(), solver);
  iteration_ = 0;
  previous_estimate_.reset();
  converged_ = false;
  const bool usable = CanRefine(*initial_);
  // A scaleless solve that cannot be refined does not undo a scaled estimate: the scaleless motions give
  // directions only, and their robust fit can fall on a consensus of one rotation axis (a long session that
  // repeats the same motions held 20 copies each of two; the scaleless fit set one group aside and read
  // the rest as rotation-degenerate). The round resumes from the scaled estimate, whose fused motions
  // decide.
  const bool resume_scaled = current_ && current_->scaled && current_->usable() && settings_.scaled_refinement;
  if (!usable && !resume_scaled) {
    // Not enough to refine: report what the motions give and wait for more.
    const VersionStatus status = initial_->usable() ? VersionStatus::kDegenerate : VersionStatus::kFailed;
    if (!current_ || !current_->scaled) current_ = *initial_;
    state_ = std::string("waiting for motions (") + Name(initial_->observability) + ")";
    return {MakeVersion(*initial_, status, {}, now_utime)};
  }
  if (!settings_.scaled_refinement) {
    current_ = *initial_;
    converged_ = Observable(*initial_) && initial_->converged;
    state_ = converged_ ? "converged (scaleless)"
                        : std::string("waiting for motions (") + Name(initial_->observability) + ")";
    return {MakeVersion(*initial_, converged_ ? VersionStatus::kConverged : VersionStatus::kDegenerate, {}, now_utime)};
  }
  state_ = "refining";
  if (current_ && current_->scaled) {
    // The scaleless estimate over all pairs, for the record; then continue from the scaled estimate.
    std::vector<CalibrationVersion> out{MakeVersion(*initial_, VersionStatus::kInitial, {}, now_utime)};
    out.push_back(MakeVersion(*current_, VersionStatus::kRefining, {}, now_utime));
    return out;
  }
  current_ = *initial_;
  return {MakeVersion(*initial_, VersionStatus::kRefining, {}, now_utime)};
}

std::vector<CalibrationVersion> Calibrator::OnFusedMotions(int version, const std::vector<SensorMotion>& motions,
                                                           int64_t now_utime) {
  if (version != awaiting_version_) return {};  // old or repeated answer
  std::vector<MotionPair> pairs;
  std::string first_failure;
  int failed = 0;
  for (const auto& m : motions) {
    if (!m.valid && failed++ == 0)
      first_failure = std::to_string(m.station_i) + "-" + std::to_string(m.station_j) + ": " + m.failure_reason;
    MotionPair p;
    if (m.scaled && PairWithLidar(m, &p)) pairs.push_back(p);
  }
  if (const auto change = DetectChange(pairs))
    return StartAfterChange(change->first, change->second, *reference_, now_utime);
  HandEyeResult before;
  if (const auto change = DetectChangeBySplit(pairs, &before))
    return StartAfterChange(change->first, change->second, before, now_utime);
  HandEyeSettings solver = settings_.solver;
  if (current_->scaled && current_->usable()) solver.previous_verdict = current_->observability;
  HandEyeResult result = SolveScaled(pairs, solver, &current_->T_camera_lidar);
  if (!result.usable()) {
    // Keep what we had; say why and wait for more motions.
    std::string why = "scaled solve failed: " + result.message;
    if (failed > 0)
      why = "fusion odometry failed for " + std::to_string(failed) + " of " + std::to_string(motions.size()) +
            " motions (first: " + first_failure + "); " + why;
    state_ = "waiting for motions (" + why + ")";
    HandEyeResult kept = *current_;
    kept.message = why;
    return {MakeVersion(kept, VersionStatus::kFailed, {}, now_utime)};
  }
  const Change change = Difference(result.T_camera_lidar, current_->T_camera_lidar);
  const std::optional<Isometry3> two_back = previous_estimate_;
  previous_estimate_ = current_->T_camera_lidar;
  current_ = result;
  ++iteration_;
  const ObservedUncertainty observed =
      ObservedPart(result.covariance, result.T_camera_lidar.linear(), result.unobservable_direction);
  const double f = settings_.tolerance_std_fraction;
  const auto below = [&](const Change& c, double fraction) {
    return c.rotation_rad * 180.0 / M_PI <
               std::max(settings_.tolerance_rotation_deg, fraction * observed.max_rotation_std_deg) &&
           c.translation_m < std::max(settings_.tolerance_translation_m, fraction * observed.max_translation_std_m);
  };
  // Fusion odometry depends on the extrinsic by steps (which tracks see which points), so the alternation
  // can settle into a cycle of two estimates instead of a point: back where it was two iterations ago,
  // with a step below the estimate's std, it has converged as far as the noise can tell.
  const bool step_small = below(change, f);
  const bool cycle =
      !step_small && two_back && below(Difference(result.T_camera_lidar, *two_back), f) && below(change, 1.0);
  const bool small = step_small || cycle;
  if (cycle) {
    std::ostringstream note;
    note.precision(3);
    note << "the alternation settled into a cycle of " << change.rotation_rad * 180.0 / M_PI << " deg / "
         << change.translation_m << " m between two estimates, within their std";
    note_ = note.str();
  }
  const bool done = small || iteration_ >= settings_.max_iterations;
  VersionStatus status = VersionStatus::kRefining;
  if (done)
    status = !Observable(result)         ? VersionStatus::kDegenerate
             : result.converged && small ? VersionStatus::kConverged
                                         : VersionStatus::kNotConverged;
  converged_ = status == VersionStatus::kConverged;
  state_ = Name(status);
  return {MakeVersion(result, status, change, now_utime)};
}

CalibrationVersion Calibrator::MakeVersion(const HandEyeResult& result, VersionStatus status, Change change,
                                           int64_t now_utime) {
  CalibrationVersion v;
  v.version = ++version_;
  v.utime = now_utime;
  v.status = status;
  v.result = result;
  v.iteration = iteration_;
  v.change_rotation_rad = change.rotation_rad;
  v.change_translation_m = change.translation_m;
  v.changes = changes_;
  if (!note_.empty()) {
    v.result.message = v.result.message.empty() ? note_ : note_ + "; " + v.result.message;
    note_.clear();
  }
  // A request lists the pairs fusion odometry is to compute: all that the newest scaleless solve used, or
  // every held pair when that solve could not be refined (the round resumes from the scaled estimate).
  if (v.asks() && initial_ && !CanRefine(*initial_)) {
    for (const auto& p : ScalelessPairs()) v.used.push_back({p.station_i, p.station_j});
  } else {
    const HandEyeResult& used_by = v.asks() && initial_ ? *initial_ : result;
    for (const auto& p : used_by.used_pairs) v.used.push_back({p.station_i, p.station_j});
  }
  for (const auto& p : result.rejected_pairs) v.not_used.push_back({p.station_i, p.station_j});
  // Pairs that this solve did not take (too few motions, not asked for, rejected before) are listed as not
  // used: stations of the held pairs are kept by fusion odometry and the coordinator by this list.
  ListHeldPairs(&v);
  dropped_since_version_.clear();
  awaiting_version_ = v.asks() ? v.version : -1;
  last_sent_utime_ = now_utime;
  last_request_.reset();
  if (v.asks()) last_request_ = v;
  return v;
}

void Calibrator::ListHeldPairs(CalibrationVersion* v) const {
  std::set<StationPair> listed(v->used.begin(), v->used.end());
  listed.insert(v->not_used.begin(), v->not_used.end());
  std::vector<StationPair> unlisted;
  for (const auto& p : ScalelessPairs()) unlisted.push_back({p.station_i, p.station_j});
  unlisted.insert(unlisted.end(), dropped_since_version_.begin(), dropped_since_version_.end());
  for (const auto& key : unlisted)
    if (listed.insert(key).second) v->not_used.push_back(key);
}

std::optional<CalibrationVersion> Calibrator::Tick(int64_t now_utime) {
  if (awaiting_version_ < 0 || !last_request_ || settings_.retry_s <= 0) return std::nullopt;
  if (now_utime - last_sent_utime_ < static_cast<int64_t>(settings_.retry_s * 1e6)) return std::nullopt;
  ++retries_;
  last_sent_utime_ = now_utime;
  return last_request_;  // same version: answered from cache if seen
}

}  // namespace fusecal
