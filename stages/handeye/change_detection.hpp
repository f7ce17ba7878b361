// Detecting that the extrinsic changed mid-session (a sensor knocked on its mount) from the motion pairs.
//
// Test of one pair. A new pair (A, B) is compared with the current estimate X = (R, t) before it enters a
// solve: its residual r = [Log(R_b^T R^T R_a R) ; (R_a - I) t + s t_a - R t_b] (the paper's A X = X B,
// handeye/pair_model.hpp) has, if X still holds, the covariance
//   C = J_A S_A J_A^T + J_B S_B J_B^T + J_X S_X J_X^T
// (the pair's own noise at the noise the estimate's residuals show, never below a floor, the translation's at
// least what its residuals show with no share put down to the rotation noise, and the estimate's covariance S_X), so
//   d^2 = r^T C^-1 r,   d^2 / k  ~  F(k, nu),   k = 6 for a metric camera motion, nu = 3 n - 3 the
// residuals each part of the noise (rotation, translation) of a solve of n pairs was estimated from, less
// its 3 unknowns (chi^2(k) for many pairs; a solve of few pairs fits its residuals too well, and the F
// quantile allows for that; chi^2(k) also where the floor holds, a noise not estimated but stated). A scaleless camera
// motion is tested on its rotation (k = 3); with test_direction also on the direction of its translation, at the scale
// that fits it best: the two components of r_t normal to that direction (k = 5; k = 3 for a turn on the spot). That
// direction comes from the images alone; but it is as noisy as the 5-point solver makes it, which the metric noise does
// not tell.
// The pair is "off" when its rotation rows or its translation rows, each tested alone (r of those rows against
// their block of C), exceed the quantile 1 - alpha / 2 of their 3 (2 for a direction) rows; a pair tested on its
// rotation alone, the quantile 1 - alpha (alpha = off_probability). A knock mostly turns or mostly shifts the sensor,
// and the six rows together dilute a shift with the rotation's noise: a 1 cm shift across a pair read d^2 = 147
// against 154 for F(6, 6), above the 117 of its translation rows at F(3, 6).
//
// Each pair is tested on arrival with its scaleless camera motion (also a pair the solve will reject as an
// outlier is tested), and again with the metric camera motion fusion odometry gives for it, whose test then
// replaces the first: fusion odometry refines the same camera motion, and the 5-point solver's own errors
// (a narrow field of view gives rotations off by 0.1-0.3 deg where the metric ones fit) are no evidence of
// a change once it has. While the newest pairs hold an off pair, they are tested against the estimate from before it
// (the reference), so that pairs after a change do not pull the estimate they are tested against.
//
// Rule (a change, not an outlier). A change makes the pair across it off (the pair that spans the change
// mixes both extrinsics, A = X B X'^-1, and shows the whole change whatever its turn), and the pairs after
// it all fit one other extrinsic X Exp(delta). So the extrinsic changed after station_i of an off pair of
// the newest `window` when the pairs after it, together, reject delta = 0: with residuals w_i whitened by
// each pair's own noise and Jacobians G_i (d w_i / d delta) of those pairs, delta_hat = -H^+ g
// (g = sum G_i^T w_i, H = sum G_i^T G_i) and the likelihood ratio
//   lambda = delta_hat^T (H^+ + S_X)^-1 delta_hat
// (S_X once: the estimate's error is common to all of them and looks like a change) exceeds the quantile 1 -
// confirm_probability on rank(H) degrees of freedom (F as above), or when they confirm the change the off pair itself
// shows (the directed test). The pair across the change sees the whole change, r_s = K delta with K = [[-I, 0], [0, -R
// R_b R^T]] (from A = X B X'^-1), while a pair after it sees only its part across its turn, r_i = -J_X delta (a
// translation dt as (R_a - I) dt). So the off pair's own delta_s = K^+ r_s (whitened) gives the direction u, and the
// pairs after it are tested along u alone:  z = a / std(a),  a = -g^T u / u^T H u,  a change when z exceeds the
// one-sided 1 - directed_confirm_probability quantile (t with the noise's degrees of freedom). Whatever the off pair
// holds, z is N(0, 1) when the pairs after it fit X, so an outlier confirms with probability beta here too. A single
// bad pair is off alone: the pairs after it fit the estimate and it stays an outlier for the solver's rejection. With
// Gaussian noise a pair is off with probability below 2 alpha and a false alarm needs the next pairs to confirm by
// either test, with the scaleless or the metric motions: below 4 alpha (beta + beta_directed) (window - 1) = 4.4e-5 per
// pair at the defaults, about one session in 75 of 300 stations. The directed test at 1e-2: a 1 cm translation after
// turns of 8-16 deg reaches z = 2.6-2.9 after two pairs (threshold 2.33 against 3.09 at 1e-3), so it is found within
// three pairs of the change in 4 of 5 sessions of each simulated scenario rather than 1-3 of 5. The likelihood ratio
// stays at 1e-3: at 1e-2 it confirmed a change 12 pairs before the camera moved in 1 of 50 synthetic sessions at
// handheld noise (0.5 deg / 5 mm; the estimate was of 5 pairs), as a fourth pair in the window did. Where
// the pair across the change was not off alone (a change near the noise), a later one was: the change is then placed
// across the pair of the newest that splits them best (ChangeDetector::Locate). A pair tells a change only across its
// turn: the rotation residual of a pair turning by theta shows about 2 sin(theta / 2) of a rotation change, and of a
// translation change dt only (R_a - I) dt, its part normal to the turn axis at that factor (0.17-0.28 for tilts of
// 10-16 deg), so a translation takes more pairs to confirm than a rotation, and changes far below the noise stay
// undetected and go into the estimate's residuals and std instead.
#pragma once

#include <deque>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "stages/handeye/handeye_types.hpp"

namespace fusecal {

struct ChangeDetectionSettings {
  bool enabled = true;
  double off_probability = 5e-4;  // alpha: chance that one test of a pair of an unchanged rig is off
  // beta: chance that pairs of an unchanged rig confirm an off pair, by the likelihood ratio of a change in any
  // direction, and by the directed test along the change the off pair shows.
  double confirm_probability = 1e-3;
  double directed_confirm_probability = 1e-2;
  int window = 3;  // newest tested pairs the rule looks at
  // The pair's noise is the noise the estimate's residuals show, at least this fraction of the nominal.
  double noise_floor_fraction = 0.05;
  // Whether a scaleless camera motion's direction is tested too (when its translation is at least
  // min_direction_length times the translation noise; a turn on the spot has no direction). Off by default:
  // a camera with a narrow field of view gets directions from the 5-point solver far noisier than its
  // metric motions (unchanged pairs off by d^2 of 100 to 2000 in the pinhole scenario, 5 false alarms in
  // 50 sessions), and the test takes its noise from the metric motions.
  bool test_direction = false;
  double min_direction_length = 10.0;
  // The pairs tested on their rotations alone while the estimate was rotation-degenerate get the change-point
  // test of handeye/split_test.hpp once it is observable, at confirm_probability, with a noise estimated from
  // at least this many residuals.
  int split_min_noise_dof = 6;

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
  bool metric = false;  // of the metric camera motion, else of the scaleless one
  double d2 = 0;        // r^T C^-1 r
  int dof = 0;
  int noise_dof = 0;  // residuals the noise of the estimate tested against was estimated from
  bool off = false;
  // Whitened by the pair's own noise (W^T W = (J_A S_A J_A^T + J_B S_B J_B^T)^-1):
  Eigen::MatrixXd whitened_jacobian;              // W J_X (dof x 6): the residual's response to delta
  Eigen::VectorXd whitened_residual;              // W r
  Matrix6 estimate_covariance = Matrix6::Zero();  // S_X of the estimate it was tested against
  // W K (dof x 6): the residual of this pair if the extrinsic changed by delta during its motion.
  Eigen::MatrixXd whitened_change_jacobian;
};

// The test of `pair` against the estimate `estimate` (its covariance and the noise its residuals showed,
// never below `noise_floor_fraction` of the nominal noise of `solver`).
PairTest TestPair(const MotionPair& pair, const HandEyeResult& estimate, const HandEyeSettings& solver,
                  const ChangeDetectionSettings& settings);

// The likelihood ratio of a common change delta over `tests` (the rule above) and its degrees of freedom.
std::pair<double, int> ChangeLikelihoodRatio(const std::vector<PairTest>& tests);

// The directed test (the rule above): z of the pairs `after` along the change that `across` shows; 0 when
// it shows none.
double DirectedChangeScore(const PairTest& across, const std::vector<PairTest>& after);

// noise_dof of a noise known (not estimated), and from which on F(k, nu) is chi^2(k) / k to 0.2 %.
inline constexpr int kKnownNoiseDof = 2000;

// The threshold of d^2 for upper-tail probability `alpha` with `dof` tested residuals whose noise was
// estimated from `noise_dof` residuals: dof times the F(dof, noise_dof) quantile.
double TestThreshold(int dof, int noise_dof, double alpha);

// P(F(d1, d2) > x).
double FUpperTail(double d1, double d2, double x);

// The chi^2 quantile for upper-tail probability `alpha` with `dof` degrees of freedom.
double ChiSquareQuantile(int dof, double alpha);

// A pair's newest test: of its scaleless camera motion until fusion odometry's metric one replaces it.
struct TestedPair {
  int station_i = -1;
  int station_j = -1;
  PairTest test;
};

// The rule above over the pairs tested since the last change, in their order of arrival.
class ChangeDetector {
 public:
  explicit ChangeDetector(ChangeDetectionSettings settings = {}) : settings_(settings) {}
  // Adds the newest test, or the metric test of a pair already there (which replaces its scaleless one; a
  // scaleless test after it is ignored); the station after which the extrinsic changed when the rule
  // decides. Each pair takes part with the test it holds.
  std::optional<int> Add(const PairTest& test);
  void Reset() { recent_.clear(); }
  // Whether the newest pairs hold an off pair (a change may be under way).
  bool Suspicious() const;
  const std::deque<TestedPair>& recent() const { return recent_; }

 private:
  // Whether the pairs after `candidate` confirm it.
  bool Confirms(const TestedPair& candidate) const;
  // The pair across the change among the newest up to `confirmed`: the split that explains them best (least
  // whitened squares: pairs before it fit the estimate, it fits K delta, the pairs after it -J_X delta).
  const TestedPair& Locate(const TestedPair& confirmed) const;

  ChangeDetectionSettings settings_;
  std::deque<TestedPair> recent_;
};

}  // namespace fusecal
