#include "stages/foundation/observed_covariance.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace fusecal {
namespace {

// Projects `u` (unit) out of the 3x3 block at `offset` when the block's variance along it marks it
// unobserved; true when it did.
bool ProjectOut(Matrix6* C, int offset, const Eigen::Vector3d& u) {
  if (!(u.norm() > 0.5)) return false;
  const double variance = u.transpose() * C->block<3, 3>(offset, offset) * u;
  if (!(variance >= kUnobservedVariance)) return false;
  Matrix6 P = Matrix6::Identity();
  P.block<3, 3>(offset, offset) -= u * u.transpose();
  *C = P * *C * P.transpose();
  return true;
}

double LargestStd(const Eigen::Matrix3d& block) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (block + block.transpose()));
  return std::sqrt(std::max(eig.eigenvalues()(2), 0.0));
}

}  // namespace

ObservedUncertainty ObservedPart(const Matrix6& covariance, const Eigen::Matrix3d& R,
                                 const Eigen::Vector3d& direction) {
  ObservedUncertainty out;
  out.covariance = 0.5 * (covariance + covariance.transpose());
  const double n = direction.norm();
  if (n > 0 && std::isfinite(n)) {
    const Eigen::Vector3d d = direction / n;
    out.rotation_projected = ProjectOut(&out.covariance, 0, (R.transpose() * d).normalized());
    out.translation_projected = ProjectOut(&out.covariance, 3, d);
  }
  out.rotation_std_deg = out.covariance.diagonal().head<3>().cwiseMax(0.0).cwiseSqrt() * 180.0 / M_PI;
  out.translation_std_m = out.covariance.diagonal().tail<3>().cwiseMax(0.0).cwiseSqrt();
  out.max_rotation_std_deg = LargestStd(out.covariance.topLeftCorner<3, 3>()) * 180.0 / M_PI;
  out.max_translation_std_m = LargestStd(out.covariance.bottomRightCorner<3, 3>());
  return out;
}

}  // namespace fusecal
