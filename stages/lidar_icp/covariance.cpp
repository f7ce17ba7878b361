#include "stages/lidar_icp/covariance.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

namespace fusecal::lidar_icp {

bool CovarianceFromHessian(const Linearization& lin, Matrix6* cov) {
  if (lin.weight_sum <= 6.0 || !lin.H.allFinite()) return false;
  Eigen::SelfAdjointEigenSolver<Matrix6> eig(lin.H);
  const Vector6 ev = eig.eigenvalues();
  if (!(ev(0) > 1e-12 * ev(5)) || !(ev(0) > 0.0)) return false;
  const double sigma2 = lin.weighted_sq / (lin.weight_sum - 6.0);
  const Matrix6 H_inv = eig.eigenvectors() * ev.cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
  *cov = sigma2 * H_inv;
  *cov = 0.5 * (*cov + cov->transpose());
  return cov->allFinite();
}

double Conditioning(const Linearization& lin, double length_m) {
  Vector6 scale;
  scale << Eigen::Vector3d::Constant(1.0 / std::max(length_m, 1e-3)), Eigen::Vector3d::Ones();
  const Matrix6 Hs = scale.asDiagonal() * lin.H * scale.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Matrix6> eig(Hs);
  const Vector6 ev = eig.eigenvalues();
  return ev(5) > 0.0 ? std::max(0.0, ev(0)) / ev(5) : 0.0;
}

void CovarianceExtent(const Matrix6& cov, double* rotation_std_rad, double* translation_std_m) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> rot(cov.topLeftCorner<3, 3>());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> tra(cov.bottomRightCorner<3, 3>());
  *rotation_std_rad = std::sqrt(std::max(0.0, rot.eigenvalues()(2)));
  *translation_std_m = std::sqrt(std::max(0.0, tra.eigenvalues()(2)));
}

}  // namespace fusecal::lidar_icp
