#include "stages/handeye/global_scale.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <sstream>

#include "stages/handeye/handeye_solver.hpp"

namespace fusecal {
namespace {

struct ScaleFit {
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double lambda = 0.0;
  double lambda_std = 0.0;
  bool determined = false;
};

// [(R_a - I)  t_a] [t; lambda] = R t_b over the pairs the scaleless solve used.
ScaleFit FitGlobalScale(const std::vector<MotionPair>& pairs, const HandEyeResult& scaleless) {
  const Eigen::Matrix3d R = scaleless.T_camera_lidar.linear();
  const int n = static_cast<int>(scaleless.used_pairs.size());
  Eigen::MatrixXd M(3 * n, 4);
  Eigen::VectorXd b(3 * n);
  for (int k = 0; k < n; ++k) {
    const MotionPair& p = pairs[scaleless.used_pairs[k].index];
    M.block<3, 3>(3 * k, 0) = p.A.linear() - Eigen::Matrix3d::Identity();
    M.block<3, 1>(3 * k, 3) = p.A.translation();
    b.segment<3>(3 * k) = R * p.B.translation();
  }
  ScaleFit fit;
  const Eigen::Matrix4d N = M.transpose() * M;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(N);
  if (n < 2 || !(eig.eigenvalues()(0) > 1e-12 * eig.eigenvalues()(3))) return fit;
  const Eigen::Vector4d x = N.ldlt().solve(M.transpose() * b);
  const int dof = 3 * n - 4;
  const double variance = dof > 0 ? (M * x - b).squaredNorm() / dof : 0.0;
  fit.t = x.head<3>();
  fit.lambda = x(3);
  fit.lambda_std = std::sqrt(std::max(variance * N.inverse()(3, 3), 0.0));
  fit.determined = std::isfinite(fit.lambda);
  return fit;
}

}  // namespace

HandEyeResult SolveGlobalScale(const std::vector<MotionPair>& pairs, const HandEyeSettings& settings) {
  HandEyeResult scaleless = SolveScaleless(pairs, settings);
  if (!scaleless.usable() || scaleless.observability == Observability::kRotationDegenerate) return scaleless;
  const ScaleFit fit = FitGlobalScale(pairs, scaleless);
  if (!fit.determined || !(fit.lambda > 0.0)) {
    std::ostringstream m;
    m << "the global camera scale is not determined by these motions"
      << (fit.determined ? " (least squares gives " + std::to_string(fit.lambda) + ", not positive)" : "") << "; "
      << scaleless.message;
    scaleless.message = m.str();
    scaleless.status = HandEyeStatus::kFailed;
    scaleless.converged = false;
    scaleless.failure_reason = {HandEyeFailure::kSolverFailed, scaleless.message};
    return scaleless;
  }
  std::vector<MotionPair> metric = pairs;
  for (auto& p : metric) {
    p.A.translation() *= fit.lambda;
    p.camera_scaled = true;
  }
  Isometry3 start = scaleless.T_camera_lidar;
  start.translation() = fit.t;
  // The scale is known only to lambda_std: every camera translation shares that relative error, which the
  // scaled solve adds to its covariance as the camera's common length scale (handeye/shared_error.hpp).
  HandEyeSettings scaled_settings = settings;
  scaled_settings.shared_camera_errors.translation_scale =
      std::hypot(settings.shared_camera_errors.translation_scale, fit.lambda_std / fit.lambda);
  HandEyeResult result = SolveScaled(metric, scaled_settings, &start);
  result.scales = {fit.lambda};
  result.scale_std_devs = {fit.lambda_std};
  std::ostringstream m;
  m << "global camera scale " << fit.lambda << " +- " << fit.lambda_std << "; " << result.message;
  result.message = m.str();
  return result;
}

}  // namespace fusecal
