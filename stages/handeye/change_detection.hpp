// Detecting that the extrinsic changed mid-session (a sensor knocked on its mount) from the motion pairs.
//
// Test of one pair. A new pair (A, B) is compared with the current estimate X = (R, t) before it enters a
// solve: its residual r = [Log(R_b^T R^T R_a R) ; (R_a - I) t + s t_a - R t_b] (the paper's A X = X B,
// handeye/pair_model.hpp) has, if X still holds, the covariance
//   C = J_A S_A J_A^T + J_B S_B J_B^T + J_X S_X J_X^T
// (the pair's own noise at the noise the estimate's residuals show, and the estimate's covariance S_X), so
//   d^2 = r^T C^-1 r,   d^2 / k  ~  F(k, nu),   k = 6 for a metric camera motion, 3 (rotation only) for a
// scaleless one, nu = 3 n - 6 the residuals the noise of a solve of n pairs was estimated from (chi^2(k)
// for many pairs; a solve of few pairs fits its residuals too well, and the F quantile allows for that).
// The pair is "off" when d^2 exceeds the quantile 1 - alpha (alpha = off_probability).
//
// Each pair is tested twice: on arrival with its scaleless camera motion (rotation only; also a pair the
// solve will reject as an outlier is tested), and with the metric camera motion fusion odometry gives for
// it (all six). It is off when either test is. While the newest pairs hold an off pair, they are tested
// against the estimate from before it (the reference), so that pairs after a change do not pull the
// estimate they are tested against.
//
// Rule (a change, not an outlier). A change makes the pair across it off (the pair that spans the change
// mixes both extrinsics, A = X B X'^-1, and shows the whole change whatever its turn), and the pairs after
// it all fit one other extrinsic X Exp(delta). So the extrinsic changed after station_i of an off pair of
// the newest `window` when the pairs after it, together, reject delta = 0: with whitened residuals w_i
// and Jacobians G_i (d w_i / d delta) of those pairs, the generalised likelihood ratio
//   lambda = g^T H^+ g,   g = sum G_i^T w_i,   H = sum G_i^T G_i,
// exceeds the quantile 1 - confirm_probability on rank(H) degrees of freedom (F as above). A single bad pair is off
// alone: the pairs after it fit the estimate and it stays an outlier for the solver's rejection. With
// Gaussian noise a pair is off with probability below 2 alpha and a false alarm needs the next pairs to
// confirm at beta: below 2 alpha beta (window - 1) = 2e-6 per pair at the defaults, about one session in
// 1600 of 300 stations.
// A pair tells a change only across its turn: the rotation residual of a pair turning by theta shows
// about 2 sin(theta / 2) of a rotation change, so changes far below the noise stay undetected and go into
// the estimate's residuals and std instead.
#pragma once

#include <deque>
#include <optional>
#include <utility>
#include <vector>

#include "handeye/handeye_types.hpp"

namespace fusecal {

struct ChangeDetectionSettings {
  bool enabled = true;
  double off_probability = 5e-4;      // alpha: chance that one test of a pair of an unchanged rig is off
  double confirm_probability = 1e-3;  // beta: chance that pairs of an unchanged rig confirm an off pair
  int window = 3;                     // newest tested pairs the rule looks at
  // The pair's noise is the noise the estimate's residuals show, at least this fraction of the nominal.
  double noise_floor_fraction = 0.1;

  // Empty when usable, else the field and what is wrong.
  std::string Validate() const;
};

// A change of the extrinsic that was detected.
struct ExtrinsicChange {
  int after_station = -1;                      // the last station before the change
  int decided_at_station = -1;                 // station_j of the pair that decided it
  Isometry3 T_before = Isometry3::Identity();  // the estimate in force until then, and its covariance
  Matrix6 covariance_before = Matrix6::Zero();
};

struct PairTest {
  int station_i = -1;
  int station_j = -1;
  double d2 = 0;  // r^T C^-1 r
  int dof = 0;
  int noise_dof = 0;  // residuals the noise of the estimate tested against was estimated from
  bool off = false;
  Eigen::MatrixXd whitened_jacobian;  // W J_X (dof x 6), W^T W = C^-1: the residual's response to delta
  Eigen::VectorXd whitened_residual;  // W r
};

// The test of `pair` against the estimate `estimate` (its covariance and the noise its residuals showed,
// never below `noise_floor_fraction` of the nominal noise of `solver`).
PairTest TestPair(const MotionPair& pair, const HandEyeResult& estimate, const HandEyeSettings& solver,
                  const ChangeDetectionSettings& settings);

// The likelihood ratio of a common change delta over `tests` (the rule above) and its degrees of freedom.
std::pair<double, int> ChangeLikelihoodRatio(const std::vector<PairTest>& tests);

// The threshold of d^2 for upper-tail probability `alpha` with `dof` tested residuals whose noise was
// estimated from `noise_dof` residuals: dof times the F(dof, noise_dof) quantile.
double TestThreshold(int dof, int noise_dof, double alpha);

// The chi^2 quantile for upper-tail probability `alpha` with `dof` degrees of freedom.
double ChiSquareQuantile(int dof, double alpha);

// The rule above over the pairs tested since the last change, in their order of arrival.
class ChangeDetector {
 public:
  explicit ChangeDetector(ChangeDetectionSettings settings = {}) : settings_(settings) {}
  // Adds the newest test, or the second test of a pair already there (off when either is); the station
  // after which the extrinsic changed when the rule decides.
  std::optional<int> Add(const PairTest& test);
  void Reset() { recent_.clear(); }
  // Whether the newest pairs hold an off pair (a change may be under way).
  bool Suspicious() const;
  const std::deque<PairTest>& recent() const { return recent_; }

 private:
  ChangeDetectionSettings settings_;
  std::deque<PairTest> recent_;
};

}  // namespace fusecal
