// The calibration loop of Ishikawa et al. (IROS 2018, III-B; docs/design.md, "The online alternation") as one
// single-threaded state machine, without a bus, threads or I/O. Events go in (a sensor motion, the metric
// camera motions fusion odometry computed for a version, the clock); versions of the extrinsic come out, each
// of which a node publishes as one EXTRINSIC:
//   a new usable pair        ->  scaleless solve (III-A-2)  ->  version k asks for the metric motions
//   fused motions for k      ->  scaled solve               ->  version k+1 asks again ... until one iteration
//                                                               changes the estimate less than the tolerance
// New pairs resume the alternation from the current scaled estimate (online refinement). An unanswered request
// is repeated after `retry_s` (fusion odometry answers repeats from its cache). At most `max_motions` pairs are
// held; beyond, the least informative are dropped for good (SelectInformativePairs), so that a round costs the
// same after an hour as after ten minutes. Every version lists every held pair as used or not used (other
// stages keep their stations by that list: the newest stations and those of at most 2 x max_motions pair
// ends), and the first version after a pair was dropped lists it as not used.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "stages/handeye/change_detection.hpp"
#include "stages/handeye/handeye_solver.hpp"

namespace fusecal {

struct CalibratorSettings {
  double tolerance_rotation_deg = 1e-3;  // converged when one iteration changes less than both
  double tolerance_translation_m = 1e-4;
  // ... or less than this fraction of the estimate's own standard deviation (largest over the axes, of
  // the observed part): with few motions each iteration moves the estimate by a part of its noise, and
  // iterating on would wander within it.
  double tolerance_std_fraction = 0.2;
  int max_iterations = 15;        // scaled iterations per round
  double retry_s = 3.0;           // repeat an unanswered request after this (0: never)
  bool scaled_refinement = true;  // false: stop at the scaleless estimate
  int max_motions = 40;           // motion pairs held at most (>= solver.min_pairs)
  HandEyeSettings solver;
  ChangeDetectionSettings change_detection;

  // Empty when usable, else what is wrong: a field above (tolerances > 0, max_iterations in [1, 1000],
  // retry_s >= 0), or solver.Validate()'s message after "solver." (both have a max_iterations).
  std::string Validate() const;
};

// One sensor's motion between two stations, as the LiDAR ICP or the camera front end (scaleless) or fusion
// odometry (metric) computed it.
struct SensorMotion {
  enum class Sensor { kCamera, kLidar };
  Sensor sensor = Sensor::kCamera;
  int station_i = -1;
  int station_j = -1;
  bool valid = false;   // false: the stage could not compute it (failure_reason says why)
  bool scaled = false;  // the camera translation is metric
  Isometry3 T_i_j = Isometry3::Identity();
  std::string failure_reason;
};

// What a version is; the values are EXTRINSIC's STATUS_* constants.
enum class VersionStatus : int8_t {
  kInitial = 0,       // the scaleless estimate over all pairs, for the record (a scaled round resumes)
  kRefining = 1,      // asks for the metric camera motions of the `used` pairs
  kConverged = 2,     // the change fell below tolerance, everything observable
  kNotConverged = 3,  // the iteration limit was reached
  kDegenerate = 4,    // best estimate, but the motions do not determine all of the extrinsic
  kFailed = 5,        // no new estimate (result.message says why)
};

// "initial", "refining", "converged", "not_converged", "degenerate", "failed" (as EXTRINSIC's names).
const char* Name(VersionStatus status);

using StationPair = std::pair<int, int>;  // (station_i, station_j) of a motion

// One version of the extrinsic.
struct CalibrationVersion {
  int version = 0;  // 1, 2, ... in the order produced; a repeated request keeps its version
  int64_t utime = 0;
  VersionStatus status = VersionStatus::kFailed;
  HandEyeResult result;
  int iteration = 0;               // scaled iterations of this round so far
  double change_rotation_rad = 0;  // between this estimate and the previous one of the round
  double change_translation_m = 0;
  std::vector<StationPair> used;         // used by the solve; for a request, the pairs asked for
  std::vector<StationPair> not_used;     // every other held pair, and those dropped since the last version
  std::vector<ExtrinsicChange> changes;  // every change detected in the session so far, oldest first
  bool asks() const { return status == VersionStatus::kRefining; }
  bool converged() const { return status == VersionStatus::kConverged; }
};

class Calibrator {
 public:
  explicit Calibrator(CalibratorSettings settings) : settings_(std::move(settings)) {}

  // A camera motion of the front end (scaleless) or a LiDAR motion. A motion completes a pair when the
  // other sensor's motion of the same stations has come (in either order); a new usable pair starts a round.
  // Repeats (a restarted stage sends its motions again) and motions of dropped pairs change nothing.
  std::vector<CalibrationVersion> OnMotion(const SensorMotion& motion, int64_t now_utime);
  // The metric camera motions that fusion odometry computed for `version`. Answers to any version but the
  // one awaited (late, repeated, from before a newer round) are ignored.
  std::vector<CalibrationVersion> OnFusedMotions(int version, const std::vector<SensorMotion>& motions,
                                                 int64_t now_utime);
  // The awaited request again when it has been unanswered for retry_s (same version).
  std::optional<CalibrationVersion> Tick(int64_t now_utime);

  // The latest scaleless (initial) and current results.
  const std::optional<HandEyeResult>& initial() const { return initial_; }
  const std::optional<HandEyeResult>& current() const { return current_; }
  bool converged() const { return converged_; }
  int awaiting_version() const { return awaiting_version_; }  // -1: no request open
  // What the loop is doing, for STATUS ("waiting for motions (...)", "refining", "converged", ...).
  const std::string& state() const { return state_; }
  // Usable pairs held, motions held per sensor, pairs dropped for good, repeated requests.
  int pairs() const { return static_cast<int>(ScalelessPairs().size()); }
  int camera_motions() const { return static_cast<int>(camera_motions_.size()); }
  int lidar_motions() const { return static_cast<int>(lidar_motions_.size()); }
  int dropped_pairs() const { return static_cast<int>(dropped_.size()); }
  int retries() const { return retries_; }
  int version() const { return version_; }
  int iteration() const { return iteration_; }
  const std::vector<ExtrinsicChange>& changes() const { return changes_; }

 private:
  struct Change {
    double rotation_rad = 0;
    double translation_m = 0;
  };
  static Change Difference(const Isometry3& a, const Isometry3& b);
  std::vector<CalibrationVersion> StartRound(int64_t now_utime);
  CalibrationVersion MakeVersion(const HandEyeResult& result, VersionStatus status, Change change, int64_t now_utime);
  std::vector<MotionPair> ScalelessPairs() const;
  // The pair of a camera motion with the LiDAR motion of the same stations; false when either is bad.
  bool PairWithLidar(const SensorMotion& camera, MotionPair* pair) const;
  // Drops pairs beyond max_motions, the least informative first.
  void LimitPairs();
  // Every held pair that `version` neither uses nor lists yet, and those dropped since the last version.
  void ListHeldPairs(CalibrationVersion* version) const;
  // Tests the pairs no solve has taken yet against the current estimate; the station after which the
  // extrinsic changed when the detector decides. Every pair is tested once.
  std::optional<StationPair> DetectChange(std::vector<MotionPair> pairs);  // (after_station, decided_at)
  // The change-point test (handeye/split_test.hpp) over the metric pairs `pairs` of the current estimate's
  // version, with the pairs the pair-by-pair test left untested as the candidates; on a change, *before is
  // the solve of the pairs before it.
  std::optional<StationPair> DetectChangeBySplit(std::vector<MotionPair> pairs, HandEyeResult* before);
  // Leaves the pairs before the change (and the one across it) out for good and starts again from the rest;
  // `before` is the estimate in force until the change.
  std::vector<CalibrationVersion> StartAfterChange(int after_station, int decided_at_station,
                                                   const HandEyeResult& before, int64_t now_utime);
  void Drop(const StationPair& key);

  CalibratorSettings settings_;
  std::map<StationPair, SensorMotion> camera_motions_, lidar_motions_;
  std::set<StationPair> dropped_;                   // dropped by LimitPairs: their repeats are ignored
  std::vector<StationPair> dropped_since_version_;  // listed once as not used, so that every pair is answered
  std::optional<HandEyeResult> initial_, current_;
  int version_ = 0;
  int awaiting_version_ = -1;  // the version whose fused motions we wait for, -1: none
  std::optional<CalibrationVersion> last_request_;
  int64_t last_sent_utime_ = 0;
  int iteration_ = 0;
  std::optional<Isometry3> previous_estimate_;  // the estimate before current_, within this round
  bool converged_ = false;
  int retries_ = 0;
  std::string state_ = "waiting for motions";
  ChangeDetector detector_{settings_.change_detection};
  // Pairs tested (or taken by a solve before there was an estimate to test them against), by the kind of
  // their camera motion: scaleless on arrival, metric in fusion odometry's answer.
  std::set<StationPair> tested_scaleless_, tested_metric_;
  // Pairs whose metric motion was not tested because the reference was the scaleless estimate (the scaled one
  // rotation-degenerate): the candidates of the change-point test while fewer than `window` pairs follow them.
  std::set<StationPair> untested_metric_;
  std::optional<HandEyeResult> reference_;  // what new pairs are tested against
  // What a new pair would be tested against now: the scaled estimate, or the scaleless one while the scaled
  // one is rotation-degenerate.
  const HandEyeResult* Reference() const;
  std::vector<ExtrinsicChange> changes_;
  std::optional<int> segment_after_;  // pairs that start at or before this station belong to the past
  std::string note_;                  // said in the next version's message (a change)
};

}  // namespace fusecal
