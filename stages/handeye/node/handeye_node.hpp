// fusecal-handeye: pairs CAMERA_MOTION and LIDAR_MOTION by station pair, solves the scaleless initial
// extrinsic (paper III-A-2), then alternates with fusion odometry (III-B-2, docs/design.md section 4):
//   publish EXTRINSIC version k  ->  fusion odometry answers FUSED_MOTIONS for version k
//   ->  solve the scaled extrinsic  ->  publish version k+1 ... until the change is below tolerance.
// New motions resume the alternation from the current estimate (online refinement). An unanswered
// version is republished after `retry_s` (idempotent: fusion odometry answers repeats from cache).
// At most `max_motions` pairs are held; beyond, the least informative are dropped for good
// (SelectInformativePairs), so that a round costs the same after an hour as after ten minutes. Every
// EXTRINSIC lists all held pairs, as used or rejected (other stages keep their stations by that list), and
// the first EXTRINSIC after a pair was dropped lists it as rejected.
#pragma once

#include <map>
#include <set>
#include <optional>

#include "fusecal/extrinsic_t.hpp"
#include "fusecal/motion_set_t.hpp"
#include "fusecal/motion_t.hpp"
#include "handeye/handeye_solver.hpp"
#include "runtime/config_reader.hpp"
#include "runtime/stage_main.hpp"
#include "runtime/work_stats.hpp"

namespace fusecal {

struct HandEyeNodeSettings {
  double tolerance_rotation_deg = 1e-3;  // converged when one iteration changes less than both
  double tolerance_translation_m = 1e-4;
  // ... or less than this fraction of the estimate's own standard deviation (largest over the axes, of
  // the observed part): with few motions each iteration moves the estimate by a part of its noise, and
  // iterating on would wander within it.
  double tolerance_std_fraction = 0.2;
  int max_iterations = 15;               // scaled iterations per round
  double retry_s = 3.0;                  // republish an unanswered version after this (0: never)
  bool scaled_refinement = true;         // false: stop at the scaleless estimate
  int max_motions = 40;                  // motion pairs held at most (>= solver.min_pairs)
  HandEyeSettings solver;

  // Empty when usable, else what is wrong: a field above (tolerances > 0, max_iterations in [1, 1000],
  // retry_s >= 0), or solver.Validate()'s message after "solver." (both have a max_iterations).
  std::string Validate() const;
};

HandEyeNodeSettings ReadHandEyeNodeSettings(ConfigReader section);

class HandEyeNode : public StageNode {
 public:
  explicit HandEyeNode(HandEyeNodeSettings settings) : settings_(std::move(settings)) {}
  void Start(Bus& bus) override;
  void Tick(Bus& bus, int64_t now_utime) override;
  StageStatus Status() const override;

  // The latest scaleless (initial) and current results, for tools that run the node in-process.
  const std::optional<HandEyeResult>& initial() const { return initial_; }
  const std::optional<HandEyeResult>& current() const { return current_; }
  bool converged() const { return converged_; }

 private:
  using PairKey = std::pair<int, int>;
  void OnMotion(Bus& bus, const motion_t& motion);
  void OnFusedMotions(Bus& bus, const motion_set_t& set);
  void StartRound(Bus& bus);
  // Change of the estimate over one scaled iteration.
  struct Change {
    double rotation_rad = 0;
    double translation_m = 0;
  };
  // `status`: extrinsic_t::STATUS_* (REFINING asks fusion odometry for the metric motions of the pairs;
  // INITIAL is the scaleless record; CONVERGED, NOT_CONVERGED, DEGENERATE and FAILED end a round).
  void Publish(Bus& bus, const HandEyeResult& result, int8_t status, Change change, bool ask);
  std::vector<MotionPair> ScalelessPairs() const;
  // The pair of a camera motion with the LiDAR motion of the same stations; false when either is bad.
  bool PairWithLidar(const motion_t& camera, MotionPair* pair) const;
  // Drops pairs beyond max_motions, the least informative first.
  void LimitPairs();
  // Lists every held pair that `msg` neither uses nor rejects as rejected, and those dropped since the
  // last EXTRINSIC (a new pair may be dropped at once: it is answered, as rejected, all the same).
  void ListHeldPairs(extrinsic_t* msg) const;

  HandEyeNodeSettings settings_;
  std::map<PairKey, motion_t> camera_motions_, lidar_motions_;
  std::set<PairKey> dropped_;  // pairs dropped by LimitPairs: their repeats are ignored
  std::vector<PairKey> dropped_since_publish_;  // listed once as rejected, so that every pair is answered
  std::optional<HandEyeResult> initial_, current_;
  int version_ = 0;
  int awaiting_version_ = -1;  // the version whose FUSED_MOTIONS we wait for, -1: none
  extrinsic_t last_published_{};
  int64_t last_sent_utime_ = 0;
  int iteration_ = 0;
  bool converged_ = false;
  std::vector<Subscription> subscriptions_;
  int retries_ = 0;
  WorkStats work_;
  std::string state_ = "waiting for motions";
};

}  // namespace fusecal
