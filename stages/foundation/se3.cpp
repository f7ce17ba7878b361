#include "se3.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace fusecal {

double RotationAngle(const Eigen::Matrix3d& R) {
  // atan2 of |sin| and cos is accurate over the whole range, unlike acos((tr-1)/2) near 0.
  const Eigen::Vector3d axis_sin(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  const double s = 0.5 * axis_sin.norm();
  const double c = 0.5 * (R.trace() - 1.0);
  return std::atan2(s, c);
}

double RotationErrorRad(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  return RotationAngle(R_a.transpose() * R_b);
}

double RotationErrorDeg(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b) {
  return RotationErrorRad(R_a, R_b) * 180.0 / M_PI;
}

Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(Eigen::Quaterniond(R).normalized());
  Eigen::Vector3d v = aa.axis() * aa.angle();
  // AngleAxis gives angles in [0, 2pi) for some quaternions; map into [-pi, pi].
  if (aa.angle() > M_PI) v = aa.axis() * (aa.angle() - 2.0 * M_PI);
  return v;
}

Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& omega) {
  const double angle = omega.norm();
  if (angle < 1e-12) return Eigen::Matrix3d::Identity() + Skew(omega);
  return Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

Isometry3 MakeIsometry(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Isometry3 T = Isometry3::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

Eigen::Matrix3d RotationFromRpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d RpyFromRotation(const Eigen::Matrix3d& R) {
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return {roll, pitch, yaw};
}

void ToRowMajor(const Isometry3& T, double out[16]) {
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[r * 4 + c] = T.matrix()(r, c);
}

Isometry3 FromRowMajor(const double in[16]) {
  Eigen::Matrix4d M;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) M(r, c) = in[r * 4 + c];
  return MakeIsometry(NearestRotation(M.topLeftCorner<3, 3>()), M.topRightCorner<3, 1>());
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& M) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

bool IsValidTransform(const Isometry3& T, double tol) {
  if (!T.matrix().allFinite()) return false;
  const Eigen::Matrix3d R = T.linear();
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < tol && R.determinant() > 0;
}

}  // namespace fusecal
