#include "handeye/change_detection.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "handeye/pair_model.hpp"

namespace fusecal {

std::string ChangeDetectionSettings::Validate() const {
  if (!(off_probability > 0 && off_probability < 0.5)) return "off_probability: must be in (0, 0.5)";
  if (!(confirm_probability > 0 && confirm_probability < 0.5)) return "confirm_probability: must be in (0, 0.5)";
  if (window < 2 || window > 100) return "window: must be in [2, 100]";
  if (!(noise_floor_fraction >= 0 && noise_floor_fraction <= 1)) return "noise_floor_fraction: must be in [0, 1]";
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

// P(F(d1, d2) > x).
double FSurvival(double d1, double d2, double x) { return IncompleteBeta(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * x)); }

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

double TestThreshold(int dof, int noise_dof, double alpha) {
  if (noise_dof >= 2000) return ChiSquareQuantile(dof, alpha);
  // d^2 / dof with a noise estimated from noise_dof residuals is F(dof, noise_dof) distributed.
  return dof * UpperQuantile([&](double x) { return FSurvival(dof, noise_dof, x); }, alpha, 1.0);
}

double ChiSquareQuantile(int dof, double alpha) {
  return UpperQuantile([&](double x) { return ChiSquareSurvival(dof, x); }, alpha, 10.0 * dof + 200);
}

PairTest TestPair(const MotionPair& pair, const HandEyeResult& estimate, const HandEyeSettings& solver,
                  const ChangeDetectionSettings& settings) {
  PairTest test;
  test.station_i = pair.station_i;
  test.station_j = pair.station_j;
  const Eigen::Matrix3d R = estimate.T_camera_lidar.linear();
  const Eigen::Vector3d t = estimate.T_camera_lidar.translation();
  handeye::NoiseModel noise;
  const double floor = settings.noise_floor_fraction;
  noise.rot_sigma_rad = std::max(estimate.noise_rot_deg, floor * solver.nominal_rotation_sigma_deg) * M_PI / 180.0;
  noise.trans_sigma_m = std::max(estimate.noise_trans_m, floor * solver.nominal_translation_sigma_m);
  // That noise is itself estimated, from about 3 residuals per pair less the 6 unknowns.
  test.noise_dof = std::max(1, 3 * static_cast<int>(estimate.used_pairs.size()) - 6);
  const Matrix6 J_X = handeye::JacobianWrtExtrinsic(pair, R);
  Matrix6 C = handeye::ResidualCovariance(pair, R, t, noise) + J_X * estimate.covariance * J_X.transpose();
  const Vector6 r = handeye::PairResidual(pair, R, t);
  // A scaleless camera motion gives its direction only: its rotation residual is tested alone.
  test.dof = pair.camera_scaled ? 6 : 3;
  const Eigen::VectorXd r_k = r.head(test.dof);
  const Eigen::MatrixXd C_k = C.topLeftCorner(test.dof, test.dof);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(C_k);
  test.d2 = r_k.dot(ldlt.solve(r_k));
  const Eigen::MatrixXd W = handeye::WhiteningMatrix(C_k);
  test.whitened_jacobian = W * J_X.topRows(test.dof);
  test.whitened_residual = W * r_k;
  if (!std::isfinite(test.d2) || ldlt.info() != Eigen::Success || !test.whitened_jacobian.allFinite()) {
    test.dof = 0;  // nothing to test (non-finite motion or covariance)
    test.d2 = 0;
    return test;
  }
  test.off = test.d2 > TestThreshold(test.dof, test.noise_dof, settings.off_probability);
  return test;
}

bool ChangeDetector::Suspicious() const {
  return std::any_of(recent_.begin(), recent_.end(), [](const PairTest& t) { return t.off; });
}

std::pair<double, int> ChangeLikelihoodRatio(const std::vector<PairTest>& tests) {
  Matrix6 H = Matrix6::Zero();
  Vector6 g = Vector6::Zero();
  for (const PairTest& t : tests) {
    H += t.whitened_jacobian.transpose() * t.whitened_jacobian;
    g += t.whitened_jacobian.transpose() * t.whitened_residual;
  }
  std::vector<Eigen::VectorXd> nulls;
  const Eigen::MatrixXd H_pinv = handeye::PseudoInverse(H, &nulls);
  return {g.dot(H_pinv * g), 6 - static_cast<int>(nulls.size())};
}

std::optional<int> ChangeDetector::Add(const PairTest& test) {
  if (!settings_.enabled || test.dof == 0) return std::nullopt;
  const auto same = std::find_if(recent_.begin(), recent_.end(), [&](const PairTest& t) {
    return t.station_i == test.station_i && t.station_j == test.station_j;
  });
  if (same != recent_.end()) {
    const bool was_off = same->off;
    if (test.dof >= same->dof) *same = test;  // the metric test replaces the rotation-only one
    same->off = was_off || test.off;
  } else {
    recent_.push_back(test);
    while (static_cast<int>(recent_.size()) > settings_.window) recent_.pop_front();
  }
  for (const PairTest& candidate : recent_) {
    if (!candidate.off) continue;
    std::vector<PairTest> after;
    for (const PairTest& t : recent_)
      if (t.station_i >= candidate.station_j) after.push_back(t);
    if (after.empty()) continue;
    const auto [lambda, dof] = ChangeLikelihoodRatio(after);
    if (dof == 0 || lambda <= TestThreshold(dof, after.back().noise_dof, settings_.confirm_probability)) continue;
    const int after_station = candidate.station_i;
    recent_.clear();
    return after_station;
  }
  return std::nullopt;
}

}  // namespace fusecal
