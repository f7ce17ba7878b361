#include "stages/handeye/pair_model.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>

namespace fusecal::handeye {

NoiseModel NominalNoise(const HandEyeSettings& settings) {
  NoiseModel n;
  n.rot_sigma_rad = settings.nominal_rotation_sigma_deg * M_PI / 180.0;
  n.trans_sigma_m = settings.nominal_translation_sigma_m;
  return n;
}

namespace {
Matrix6 IsotropicCovariance(const NoiseModel& noise) {
  Matrix6 C = Matrix6::Zero();
  C.topLeftCorner<3, 3>().diagonal().setConstant(noise.rot_sigma_rad * noise.rot_sigma_rad);
  C.bottomRightCorner<3, 3>().diagonal().setConstant(noise.trans_sigma_m * noise.trans_sigma_m);
  return C;
}
}  // namespace

Matrix6 CameraCovariance(const MotionPair& pair, const NoiseModel& noise) {
  if (pair.cov_A) return *pair.cov_A;
  Matrix6 C = IsotropicCovariance(noise);
  if (const auto& by_axis = noise.rotation_by_axis) {
    const Eigen::Matrix3d& R = by_axis->R_camera_lidar;
    C.topLeftCorner<3, 3>() = 0.5 * R * RotationResidualCovariance(pair, *by_axis) * R.transpose();
  }
  return C;
}

Matrix6 LidarCovariance(const MotionPair& pair, const NoiseModel& noise) {
  if (pair.cov_B) return *pair.cov_B;
  Matrix6 C = IsotropicCovariance(noise);
  if (noise.rotation_by_axis) C.topLeftCorner<3, 3>() = 0.5 * RotationResidualCovariance(pair, *noise.rotation_by_axis);
  return C;
}

bool AllHaveCovariances(const std::vector<MotionPair>& pairs) {
  for (const auto& p : pairs)
    if (!p.cov_A || !p.cov_B) return false;
  return !pairs.empty();
}

Eigen::Vector3d RotationResidual(const MotionPair& pair, const Eigen::Matrix3d& R) {
  const Eigen::Matrix3d Ra = pair.A.linear();
  const Eigen::Matrix3d Rb = pair.B.linear();
  return LogSO3(Rb.transpose() * R.transpose() * Ra * R);
}

Eigen::Vector3d TranslationResidual(const MotionPair& pair, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                    double scale) {
  const Eigen::Matrix3d Ra = pair.A.linear();
  return (Ra - Eigen::Matrix3d::Identity()) * t + scale * pair.A.translation() - R * pair.B.translation();
}

Vector6 PairResidual(const MotionPair& pair, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Vector6 r;
  r << RotationResidual(pair, R), TranslationResidual(pair, R, t);
  return r;
}

Matrix6 JacobianWrtA(const MotionPair& pair, const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Matrix6 J = Matrix6::Zero();
  J.topLeftCorner<3, 3>() = R.transpose();
  J.bottomLeftCorner<3, 3>() = -pair.A.linear() * Skew(t);
  J.bottomRightCorner<3, 3>().setIdentity();
  return J;
}

Matrix6 JacobianWrtB(const MotionPair& pair, const Eigen::Matrix3d& R) {
  Matrix6 J = Matrix6::Zero();
  J.topLeftCorner<3, 3>() = -Eigen::Matrix3d::Identity();
  J.bottomRightCorner<3, 3>() = -R;
  return J;
}

Matrix6 ResidualCovariance(const MotionPair& pair, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                           const NoiseModel& noise) {
  const Matrix6 Ja = JacobianWrtA(pair, R, t);
  const Matrix6 Jb = JacobianWrtB(pair, R);
  const Matrix6 C =
      Ja * CameraCovariance(pair, noise) * Ja.transpose() + Jb * LidarCovariance(pair, noise) * Jb.transpose();
  return 0.5 * (C + C.transpose());
}

Matrix6 JacobianWrtExtrinsic(const MotionPair& pair, const Eigen::Matrix3d& R) {
  Matrix6 J = Matrix6::Zero();
  J.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() - pair.B.linear().transpose();
  J.bottomLeftCorner<3, 3>() = R * Skew(pair.B.translation());
  J.bottomRightCorner<3, 3>() = pair.A.linear() - Eigen::Matrix3d::Identity();
  return J;
}

Eigen::MatrixXd WhiteningMatrix(const Eigen::MatrixXd& C) {
  const Eigen::Index n = C.rows();
  Eigen::MatrixXd S = 0.5 * (C + C.transpose());
  // Regularise: floor eigenvalues at a tiny fraction of the largest so that L exists.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(S);
  const double max_ev = std::max(eig.eigenvalues().maxCoeff(), 1e-300);
  if (eig.eigenvalues().minCoeff() < 1e-12 * max_ev) {
    Eigen::VectorXd ev = eig.eigenvalues().cwiseMax(1e-12 * max_ev);
    S = eig.eigenvectors() * ev.asDiagonal() * eig.eigenvectors().transpose();
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(S);
  const Eigen::MatrixXd L = llt.matrixL();
  return L.triangularView<Eigen::Lower>().solve(Eigen::MatrixXd::Identity(n, n));
}

Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& info, std::vector<Eigen::VectorXd>* nulls, bool square_root) {
  constexpr double kNullTolerance = 1e-12;  // eigenvalue relative to the largest
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (info + info.transpose()));
  const double max_ev = eig.eigenvalues().cwiseAbs().maxCoeff();
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(info.rows(), info.cols());
  for (int k = 0; k < info.rows(); ++k) {
    const Eigen::VectorXd v = eig.eigenvectors().col(k);
    const double ev = eig.eigenvalues()(k);
    if (max_ev > 0.0 && ev > kNullTolerance * max_ev)
      C += v * v.transpose() / (square_root ? std::sqrt(ev) : ev);
    else if (nulls)
      nulls->push_back(v);
  }
  return C;
}

}  // namespace fusecal::handeye
