#include "stages/handeye/rotation_solver.hpp"

#include <Eigen/SVD>
#include <cmath>

namespace fusecal::handeye {
namespace {

Eigen::Matrix3d KabschFromCrossCovariance(const Eigen::Matrix3d& H) {
  // max tr(R^T H), H = U S V^T  ->  R = U diag(1, 1, det(U V^T)) V^T.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

}  // namespace

Eigen::Matrix3d RotationFromAxes(const std::vector<MotionPair>& pairs) {
  std::vector<Eigen::Vector3d> wa, wb;
  for (const auto& p : pairs) {
    wa.push_back(LogSO3(p.A.linear()));
    wb.push_back(LogSO3(p.B.linear()));
  }
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < wa.size(); ++i) H += wa[i] * wb[i].transpose();
  const Eigen::Matrix3d R1 = KabschFromCrossCovariance(H);
  // Second pass: near pi, Log may return -k for one sensor and +k for the other.
  H.setZero();
  for (size_t i = 0; i < wa.size(); ++i) {
    const double sign = wa[i].dot(R1 * wb[i]) < 0.0 ? -1.0 : 1.0;
    H += sign * wa[i] * wb[i].transpose();
  }
  return KabschFromCrossCovariance(H);
}

Eigen::Matrix3d AlignAxis(const Eigen::Matrix3d& R_init, const Eigen::Vector3d& k_b, const Eigen::Vector3d& k_a) {
  const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(R_init * k_b.normalized(), k_a.normalized());
  return q.toRotationMatrix() * R_init;
}

bool RotationAboutCommonAxis(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R0,
                             const Eigen::Vector3d& k_b_in, Eigen::Matrix3d* R) {
  const int n = static_cast<int>(pairs.size());
  if (n < 2) return false;
  const Eigen::Vector3d k_b = k_b_in.normalized();
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - k_b * k_b.transpose();
  Eigen::MatrixXd M(3 * n, 5);
  Eigen::VectorXd rhs(3 * n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d Ra = pairs[i].A.linear();
    const Eigen::Vector3d ta = pairs[i].A.translation();
    const Eigen::Vector3d tb = pairs[i].B.translation();
    M.block<3, 3>(3 * i, 0) = Ra - Eigen::Matrix3d::Identity();
    M.block<3, 1>(3 * i, 3) = -R0 * P * tb;
    M.block<3, 1>(3 * i, 4) = -R0 * k_b.cross(tb);
    rhs.segment<3>(3 * i) = R0 * k_b * k_b.dot(tb) - ta;
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const double smax = svd.singularValues()(0);
  if (!(smax > 0.0)) return false;
  svd.setThreshold(1e-9);
  // (c, s) must not move along a null direction; t along the axis (always null) is harmless.
  const Eigen::MatrixXd& V = svd.matrixV();
  for (int k = 0; k < 5; ++k)
    if (svd.singularValues()(k) <= 1e-9 * smax && V.block<2, 1>(3, k).norm() > 1e-6) return false;
  const Eigen::VectorXd x = svd.solve(rhs);
  const double c = x(3), s = x(4);
  if (!(std::hypot(c, s) > 1e-9)) return false;
  *R = R0 * ExpSO3(std::atan2(s, c) * k_b);
  return true;
}

}  // namespace fusecal::handeye
