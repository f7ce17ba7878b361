#include "stages/handeye/change_detection.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "stages/handeye/pair_model.hpp"

namespace fusecal {

std::string ChangeDetectionSettings::Validate() const {
  if (!(off_probability > 0 && off_probability < 0.5)) return "off_probability: must be in (0, 0.5)";
  if (!(confirm_probability > 0 && confirm_probability < 0.5)) return "confirm_probability: must be in (0, 0.5)";
  if (!(directed_confirm_probability > 0 && directed_confirm_probability < 0.5))
    return "directed_confirm_probability: must be in (0, 0.5)";
  if (window < 2 || window > 100) return "window: must be in [2, 100]";
  if (!(noise_floor_fraction >= 0 && noise_floor_fraction <= 1)) return "noise_floor_fraction: must be in [0, 1]";
  if (!(min_direction_length >= 0 && min_direction_length < 1e6)) return "min_direction_length: must be >= 0";
  if (split_min_noise_dof < 1 || split_min_noise_dof > 1000) return "split_min_noise_dof: must be in [1, 1000]";
  return "";
}

namespace {

// P(chi^2(k) > x) for an integer k, in closed form: a finite series after erfc for odd k.
double ChiSquareSurvival(int k, double x) {
  const double h = 0.5 * x;
  double sum = 0;
  if (k % 2 == 0) {
    double term = 1;
    for (int i = 0; i < k / 2; ++i) {
      sum += term;
      term *= h / (i + 1);
    }
    return std::exp(-h) * sum;
  }
  for (int i = 1; i <= (k - 1) / 2; ++i) sum += std::pow(h, i - 0.5) / std::tgamma(i + 0.5);
  return std::erfc(std::sqrt(h)) + std::exp(-h) * sum;
}

// The regularised incomplete beta function I_x(a, b), by its continued fraction (Lentz's method).
double IncompleteBeta(double a, double b, double x) {
  if (x <= 0) return 0;
  if (x >= 1) return 1;
  if (x > (a + 1) / (a + b + 2)) return 1 - IncompleteBeta(b, a, 1 - x);
  const double front =
      std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log(1 - x)) / a;
  const double tiny = 1e-300;
  double c = 1, d = 1 - (a + b) * x / (a + 1);
  d = 1 / (std::abs(d) < tiny ? tiny : d);
  double f = d;
  for (int m = 1; m < 300; ++m) {
    for (int odd = 0; odd < 2; ++odd) {
      const double num = odd ? -(a + m) * (a + b + m) * x / ((a + 2 * m) * (a + 2 * m + 1))
                             : m * (b - m) * x / ((a + 2 * m - 1) * (a + 2 * m));
      d = 1 + num * d;
      d = 1 / (std::abs(d) < tiny ? tiny : d);
      c = 1 + num / c;
      if (std::abs(c) < tiny) c = tiny;
      f *= c * d;
    }
    if (std::abs(c * d - 1) < 1e-14) break;
  }
  return front * f;
}

// The x with survival(x) = alpha, by bisection from [0, hi] (hi doubled until it brackets x).
template <typename Survival>
double UpperQuantile(const Survival& survival, double alpha, double hi) {
  double lo = 0;
  while (survival(hi) > alpha && hi < 1e12) hi *= 2;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (survival(mid) > alpha ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

double FUpperTail(double d1, double d2, double x) { return IncompleteBeta(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * x)); }

double TestThreshold(int dof, int noise_dof, double alpha) {
  if (noise_dof >= kKnownNoiseDof) return ChiSquareQuantile(dof, alpha);
  // d^2 / dof with a noise estimated from noise_dof residuals is F(dof, noise_dof) distributed.
  return dof * UpperQuantile([&](double x) { return FUpperTail(dof, noise_dof, x); }, alpha, 1.0);
}

double ChiSquareQuantile(int dof, double alpha) {
  return UpperQuantile([&](double x) { return ChiSquareSurvival(dof, x); }, alpha, 10.0 * dof + 200);
}

namespace {

// The residuals a pair is tested on, as rows M (k x 6) of [r_rot ; r_t], and the pair with a metric camera
// translation. A metric camera motion: all six. A scaleless one gives the direction u of its translation
// only: the scale s that fits it best at (R, t) is taken as measured and the residual along u, which s
// absorbs, is left out (r_t in the plane Q normal to u, 2 of 3); without a direction (a turn on the spot,
// a translation below `min_length_m` at that scale) the rotation alone.
Eigen::MatrixXd TestedResiduals(MotionPair* pair, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                double min_length_m) {
  if (pair->camera_scaled) return Eigen::MatrixXd::Identity(6, 6);
  Eigen::MatrixXd rotation_only = Eigen::MatrixXd::Zero(3, 6);
  rotation_only.leftCols(3).setIdentity();
  const Eigen::Vector3d t_a = pair->A.translation();
  if (!(t_a.norm() > 0)) return rotation_only;
  const Eigen::Vector3d u = t_a.normalized();
  // r_t = (R_a - I) t + s u - R t_b, least at s = u . (R t_b - (R_a - I) t).
  const double s = u.dot(R * pair->B.translation() - (pair->A.linear() - Eigen::Matrix3d::Identity()) * t);
  if (!(s > min_length_m)) return rotation_only;
  pair->A.translation() = s * u;
  pair->camera_scaled = true;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(u * u.transpose(), Eigen::ComputeFullU);
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(5, 6);
  M.topLeftCorner(3, 3).setIdentity();
  M.bottomRightCorner(2, 3) = svd.matrixU().rightCols(2).transpose();  // the plane normal to u
  return M;
}

}  // namespace

PairTest TestPair(const MotionPair& measured, const HandEyeResult& estimate, const HandEyeSettings& solver,
                  const ChangeDetectionSettings& settings) {
  PairTest test;
  test.station_i = measured.station_i;
  test.station_j = measured.station_j;
  test.metric = measured.camera_scaled;
  const Eigen::Matrix3d R = estimate.T_camera_lidar.linear();
  const Eigen::Vector3d t = estimate.T_camera_lidar.translation();
  handeye::NoiseModel noise;
  const double floor = settings.noise_floor_fraction;
  const double rot_floor_deg = floor * solver.nominal_rotation_sigma_deg;
  const double trans_floor_m = floor * solver.nominal_translation_sigma_m;
  const int n = static_cast<int>(estimate.used_pairs.size());
  // The translation noise is at least what the translation residuals show with no share put down to the rotation
  // noise. The solver's estimate subtracts that share, 2 sigma_rot^2 |t|^2, and with few pairs at handheld noise
  // (0.5 deg, a lever arm of 0.67 m) the share was the whole residual: the estimate fell to nothing, the floor held,
  // and pairs of an unchanged rig were off by d^2 of 100 (false alarms at ten times the designed rate, in synthetic
  // sessions at that noise: docs/benchmarks.md, "Recalibration").
  const double shown_trans_m = n > 1 ? estimate.residual_rms_trans_m * std::sqrt(n / (6.0 * (n - 1))) : 0.0;
  const double trans_noise_m = std::max(estimate.noise_trans_m, shown_trans_m);
  noise.rot_sigma_rad = std::max(estimate.noise_rot_deg, rot_floor_deg) * M_PI / 180.0;
  noise.trans_sigma_m = std::max(trans_noise_m, trans_floor_m);
  // That noise is itself estimated: rotation and translation each from the 3 n residuals of its part of the
  // solve less its 3 unknowns; where the floor holds both, it is a known value (chi^2).
  const bool floored = estimate.noise_rot_deg <= rot_floor_deg && trans_noise_m <= trans_floor_m;
  const int nu = std::max(1, 3 * n - 3);
  test.noise_dof = floored ? kKnownNoiseDof : std::min(kKnownNoiseDof, nu);
  MotionPair pair = measured;
  const double min_length = settings.test_direction ? settings.min_direction_length * noise.trans_sigma_m
                                                    : std::numeric_limits<double>::infinity();
  const Eigen::MatrixXd M = TestedResiduals(&pair, R, t, min_length);
  const Matrix6 J_X = handeye::JacobianWrtExtrinsic(pair, R);
  const Matrix6 C_pair = handeye::ResidualCovariance(pair, R, t, noise);
  const Matrix6 C = C_pair + J_X * estimate.covariance * J_X.transpose();
  const Eigen::VectorXd r_k = M * handeye::PairResidual(pair, R, t);
  const Eigen::MatrixXd C_k = M * C * M.transpose();
  test.dof = static_cast<int>(M.rows());
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(C_k);
  test.d2 = r_k.dot(ldlt.solve(r_k));
  // The pairs tested against one estimate share its error: the rule whitens by the pair's own noise and
  // takes the estimate's covariance once (ChangeLikelihoodRatio).
  const Eigen::MatrixXd W = handeye::WhiteningMatrix(M * C_pair * M.transpose());
  test.estimate_covariance = estimate.covariance;
  test.whitened_jacobian = W * M * J_X;
  test.whitened_residual = W * r_k;
  // The pair across a change: A = X B X'^-1 with X' = (R Exp(phi), t + tau) gives r = [-phi ; -R R_b R^T tau].
  Matrix6 K = -Matrix6::Identity();
  K.bottomRightCorner<3, 3>() = -R * pair.B.linear() * R.transpose();
  test.whitened_change_jacobian = W * M * K;
  if (!std::isfinite(test.d2) || ldlt.info() != Eigen::Success || !test.whitened_jacobian.allFinite() ||
      !test.whitened_change_jacobian.allFinite()) {
    test.dof = 0;  // nothing to test (non-finite motion or covariance)
    test.d2 = 0;
    return test;
  }
  // Rotation and translation each against the noise estimated for it: a change shows mostly in one part (a knock
  // turns or shifts the sensor), where a test of all six rows dilutes it with the other part's noise; at alpha / 2
  // each, a pair of an unchanged rig is off with probability below alpha still.
  const double alpha = settings.off_probability;
  const int rotation_rows = 3;
  const int translation_rows = test.dof - rotation_rows;
  const auto part_d2 = [&](int first, int rows) {
    const Eigen::VectorXd r = r_k.segment(first, rows);
    return r.dot(C_k.block(first, first, rows, rows).ldlt().solve(r));
  };
  if (translation_rows == 0) {
    test.off = test.d2 > TestThreshold(test.dof, test.noise_dof, alpha);
  } else {
    test.off = part_d2(0, rotation_rows) > TestThreshold(rotation_rows, test.noise_dof, alpha / 2) ||
               part_d2(rotation_rows, translation_rows) > TestThreshold(translation_rows, test.noise_dof, alpha / 2);
  }
  return test;
}

bool ChangeDetector::Suspicious() const {
  return std::any_of(recent_.begin(), recent_.end(), [](const TestedPair& t) { return t.test.off; });
}

namespace {

// Over `tests`, what they say of a common change delta: H = sum G_i^T G_i and g = sum G_i^T w_i.
std::pair<Matrix6, Vector6> Information(const std::vector<PairTest>& tests) {
  Matrix6 H = Matrix6::Zero();
  Vector6 g = Vector6::Zero();
  for (const PairTest& t : tests) {
    H += t.whitened_jacobian.transpose() * t.whitened_jacobian;
    g += t.whitened_jacobian.transpose() * t.whitened_residual;
  }
  return {H, g};
}

}  // namespace

std::pair<double, int> ChangeLikelihoodRatio(const std::vector<PairTest>& tests) {
  if (tests.empty()) return {0.0, 0};
  const auto [H, g] = Information(tests);
  // delta_hat = -H^+ g (pairs after a change show r_i = -J_X delta) with the covariance H^+ of their own
  // noise, plus S_X: the estimate they are tested against errs by e ~ N(0, S_X), which shows in every
  // one of them as a change of -e would. Over the directions H sees (V):
  //   lambda = delta_hat^T (H^+ + S_X)^-1 delta_hat.
  std::vector<Eigen::VectorXd> nulls;
  const Eigen::MatrixXd H_pinv = handeye::PseudoInverse(H, &nulls);
  const Vector6 delta = -H_pinv * g;
  const Eigen::SelfAdjointEigenSolver<Matrix6> eig(H);
  const int rank = 6 - static_cast<int>(nulls.size());
  if (rank == 0) return {0.0, 0};
  const Eigen::MatrixXd V = eig.eigenvectors().rightCols(rank);  // eigenvalues ascending
  const Eigen::MatrixXd C = V.transpose() * (H_pinv + tests.back().estimate_covariance) * V;
  const Eigen::VectorXd d = V.transpose() * delta;
  return {d.dot(C.ldlt().solve(d)), rank};
}

double DirectedChangeScore(const PairTest& across, const std::vector<PairTest>& after) {
  const Eigen::MatrixXd& K = across.whitened_change_jacobian;
  if (after.empty() || K.cols() != 6 || K.rows() != across.whitened_residual.size() || K.rows() == 0) return 0;
  const Eigen::VectorXd u = handeye::PseudoInverse(K.transpose() * K) * (K.transpose() * across.whitened_residual);
  const auto [H, g] = Information(after);
  const double spread = u.dot(H * u);
  if (!(spread > 0) || !std::isfinite(spread)) return 0;
  // The size a of delta = a u that the pairs after it show, a = -u^T g / u^T H u (r_i = -J_X delta), and
  // its variance: their own noise, 1 / u^T H u, and the estimate's error they share.
  const double a = -g.dot(u) / spread;
  const Vector6 Hu = H * u;
  const double variance = 1.0 / spread + Hu.dot(after.back().estimate_covariance * Hu) / (spread * spread);
  return a / std::sqrt(variance);
}

bool ChangeDetector::Confirms(const TestedPair& candidate) const {
  std::vector<PairTest> after;
  for (const TestedPair& t : recent_)
    if (t.station_i >= candidate.station_j) after.push_back(t.test);
  if (after.empty()) return false;
  const int noise_dof = after.back().noise_dof;
  const auto [lambda, dof] = ChangeLikelihoodRatio(after);
  if (dof > 0 && lambda > TestThreshold(dof, noise_dof, settings_.confirm_probability)) return true;
  // One-sided: z > c with P = beta is z^2 > c^2 with P = 2 beta on one degree of freedom.
  const double z = DirectedChangeScore(candidate.test, after);
  return z > 0 && z * z > TestThreshold(1, noise_dof, 2 * settings_.directed_confirm_probability);
}

const TestedPair& ChangeDetector::Locate(const TestedPair& confirmed) const {
  const TestedPair* best = &confirmed;
  double best_cost = std::numeric_limits<double>::infinity();
  for (const TestedPair& across : recent_) {
    if (across.station_j > confirmed.station_j) continue;
    // Pairs before it fit the estimate (w_i ~ 0), it fits K delta, the pairs after it -G_i delta.
    double cost = 0;
    Eigen::MatrixXd A(0, 6);
    Eigen::VectorXd b(0);
    const auto append = [&](const Eigen::MatrixXd& rows, const Eigen::VectorXd& values) {
      A.conservativeResize(A.rows() + rows.rows(), Eigen::NoChange);
      A.bottomRows(rows.rows()) = rows;
      b.conservativeResize(b.size() + values.size());
      b.tail(values.size()) = values;
    };
    for (const TestedPair& t : recent_) {
      const PairTest& e = t.test;
      if (t.station_j <= across.station_i) cost += e.whitened_residual.squaredNorm();
      if (&t == &across) append(e.whitened_change_jacobian, e.whitened_residual);
      if (t.station_i >= across.station_j) append(-e.whitened_jacobian, e.whitened_residual);
    }
    const Vector6 delta = handeye::PseudoInverse(A.transpose() * A) * (A.transpose() * b);
    cost += (A * delta - b).squaredNorm();
    if (cost < best_cost) best_cost = cost, best = &across;
  }
  return *best;
}

std::optional<int> ChangeDetector::Add(const PairTest& test) {
  if (!settings_.enabled || test.dof == 0) return std::nullopt;
  const auto same = std::find_if(recent_.begin(), recent_.end(), [&](const TestedPair& t) {
    return t.station_i == test.station_i && t.station_j == test.station_j;
  });
  if (same != recent_.end()) {
    // The metric camera motion of a pair replaces its scaleless one, which the front end's 5-point solver gave
    // alone: a scaleless motion off by the solver's error (a narrow field of view) is not evidence once
    // fusion odometry refined the same motion.
    if (same->test.metric && !test.metric) return std::nullopt;
    same->test = test;
  } else {
    recent_.push_back({test.station_i, test.station_j, test});
    while (static_cast<int>(recent_.size()) > settings_.window) recent_.pop_front();
  }
  for (const TestedPair& candidate : recent_) {
    if (!candidate.test.off || !Confirms(candidate)) continue;
    const int after_station = Locate(candidate).station_i;
    recent_.clear();
    return after_station;
  }
  return std::nullopt;
}

}  // namespace fusecal
