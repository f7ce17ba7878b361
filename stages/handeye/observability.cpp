#include "stages/handeye/observability.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <initializer_list>

namespace fusecal::handeye {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
struct BlockStd {
  double max_std = 0.0;
  double min_std = 0.0;  // the best-observed direction's
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
};

// Largest standard deviation of a 3-parameter block: infinite when a null vector touches the block.
BlockStd AnalyzeBlock(const Eigen::Matrix3d& cov, const std::vector<Eigen::Vector3d>& null_parts) {
  BlockStd out;
  double best = 1e-6;
  for (const auto& v : null_parts) {
    if (v.norm() > best) {
      best = v.norm();
      out.max_std = kInf;
      out.direction = v.normalized();
    }
  }
  if (out.max_std == kInf) return out;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (cov + cov.transpose()));
  out.max_std = std::sqrt(std::max(eig.eigenvalues()(2), 0.0));
  out.min_std = std::sqrt(std::max(eig.eigenvalues()(0), 0.0));
  out.direction = eig.eigenvectors().col(2);
  return out;
}

Eigen::Matrix3d RotationInformation(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R,
                                    const NoiseModel& noise) {
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  for (const auto& p : pairs) {
    const Eigen::Matrix3d C = ResidualCovariance(p, R, Eigen::Vector3d::Zero(), noise).topLeftCorner<3, 3>();
    const Eigen::Matrix3d J = Eigen::Matrix3d::Identity() - p.B.linear().transpose();
    info += J.transpose() * C.inverse() * J;
  }
  return info;
}

// The threshold a standard deviation is compared with: moved by the hysteresis away from the previous
// verdict, so that a session near a threshold keeps its verdict (`degenerate_kinds`: the verdicts under
// which this part counts as unobserved).
double Threshold(double threshold, const HandEyeSettings& s, std::initializer_list<Observability> degenerate_kinds) {
  if (!s.previous_verdict || *s.previous_verdict == Observability::kTooFewMotions) return threshold;
  for (const Observability kind : degenerate_kinds)
    if (*s.previous_verdict == kind) return threshold * (1.0 - s.verdict_hysteresis);
  return threshold * (1.0 + s.verdict_hysteresis);
}

void Verdict(const BlockStd& rot, const BlockStd& trans, const Eigen::Matrix3d& R, const HandEyeSettings& settings,
             const VarianceFactor& variance_factor, ObservabilityReport* report) {
  report->rotation_std_deg = rot.max_std * std::sqrt(std::max(variance_factor.rotation, 1.0)) * 180.0 / M_PI;
  report->translation_std_m = trans.max_std * std::sqrt(std::max(variance_factor.translation, 1.0));
  // Motions that lack an axis leave one direction far weaker than the others; noise alone, all alike.
  const bool lacks_an_axis = !(rot.max_std <= settings.degenerate_rotation_anisotropy * rot.min_std);
  if (lacks_an_axis && report->rotation_std_deg >
                           Threshold(settings.max_rotation_std_deg, settings, {Observability::kRotationDegenerate})) {
    report->verdict = Observability::kRotationDegenerate;
    report->direction = (R * rot.direction).normalized();  // LiDAR-frame axis -> camera frame
  } else if (report->translation_std_m >
             Threshold(settings.max_translation_std_m, settings,
                       {Observability::kRotationDegenerate, Observability::kTranslationPartlyUnobservable})) {
    report->verdict = Observability::kTranslationPartlyUnobservable;
    report->direction = trans.direction.normalized();
  }
}

}  // namespace

ObservabilityReport AnalyzeScaled(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R,
                                  const Eigen::Vector3d& t, const NoiseModel& noise, const HandEyeSettings& settings,
                                  const VarianceFactor& variance_factor) {
  Eigen::MatrixXd info = Eigen::MatrixXd::Zero(6, 6);
  for (const auto& p : pairs) {
    const Matrix6 J = JacobianWrtExtrinsic(p, R);
    info += J.transpose() * ResidualCovariance(p, R, t, noise).inverse() * J;
  }
  std::vector<Eigen::VectorXd> nulls;
  const Eigen::MatrixXd C = PseudoInverse(info, &nulls);
  ObservabilityReport report;
  std::vector<Eigen::Vector3d> rot_nulls, trans_nulls;
  for (const auto& v : nulls) {
    report.null_directions.push_back(v);
    rot_nulls.push_back(v.head<3>());
    trans_nulls.push_back(v.tail<3>());
  }
  Verdict(AnalyzeBlock(C.topLeftCorner<3, 3>(), rot_nulls), AnalyzeBlock(C.bottomRightCorner<3, 3>(), trans_nulls), R,
          settings, variance_factor, &report);
  return report;
}

ObservabilityReport AnalyzeScaleless(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R,
                                     const LinearTranslation& lt, const NoiseModel& noise,
                                     const HandEyeSettings& settings, const VarianceFactor& variance_factor) {
  std::vector<Eigen::VectorXd> nulls;
  const Eigen::Matrix3d C_rr = PseudoInverse(RotationInformation(pairs, R, noise), &nulls);
  const double var_t = 2.0 * noise.trans_sigma_m * noise.trans_sigma_m;
  const Eigen::Matrix3d C_tt = var_t * lt.N_pinv + lt.dt_drot * C_rr * lt.dt_drot.transpose();
  ObservabilityReport report;
  std::vector<Eigen::Vector3d> rot_nulls, trans_nulls;
  for (const auto& v : nulls) {
    Vector6 n;
    n << v, lt.dt_drot * v;
    report.null_directions.push_back(n.normalized());
    rot_nulls.push_back(v);
    trans_nulls.push_back(lt.dt_drot * v);
  }
  for (const auto& v : lt.null_directions) {
    Vector6 n;
    n << Eigen::Vector3d::Zero(), v;
    report.null_directions.push_back(n);
    trans_nulls.push_back(v);
  }
  Verdict(AnalyzeBlock(C_rr, rot_nulls), AnalyzeBlock(C_tt, trans_nulls), R, settings, variance_factor, &report);
  return report;
}

NoiseModel VerdictNoise(const NoiseModel& nominal, const NoiseModel& estimated) {
  NoiseModel n;  // isotropic: the verdict keeps the pooled sigma
  n.rot_sigma_rad = std::max(nominal.rot_sigma_rad, estimated.rot_sigma_rad);
  n.trans_sigma_m = std::max(nominal.trans_sigma_m, estimated.trans_sigma_m);
  return n;
}

double WeakestRotationFromAxes(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R, const NoiseModel& noise,
                               Eigen::Vector3d* axis_b) {
  std::vector<Eigen::VectorXd> nulls;
  const Eigen::Matrix3d C = PseudoInverse(RotationInformation(pairs, R, noise), &nulls);
  std::vector<Eigen::Vector3d> parts(nulls.begin(), nulls.end());
  const BlockStd b = AnalyzeBlock(C, parts);
  *axis_b = b.direction;
  return b.max_std;
}

}  // namespace fusecal::handeye
