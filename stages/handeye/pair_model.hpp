// Residuals of one motion pair, their first-order covariance and whitening (internal to the solver).
//
// From A X = X B (paper, hand-eye formulation):
//   rotation     R_a R = R R_b            ->  r_rot = Log(R_b^T R^T R_a R)            (3, radians)
//   translation  R_a t + s t_a = R t_b + t ->  r_t   = (R_a - I) t + s t_a - R t_b     (3, metres)
// with s = 1 for scaled camera motions.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "stages/handeye/handeye_types.hpp"
#include "stages/handeye/rotation_noise.hpp"

namespace fusecal::handeye {

// Noise per sensor motion, used where a pair carries no covariance: isotropic per axis, or for the rotation
// by direction where the residuals showed it (rotation_noise.hpp; both sensors share it half and half).
struct NoiseModel {
  double rot_sigma_rad = 0.0;
  double trans_sigma_m = 0.0;
  std::optional<RotationNoiseByAxis> rotation_by_axis;
};

NoiseModel NominalNoise(const HandEyeSettings& settings);

// cov_A / cov_B when present, otherwise diag(sigma_rot^2 I, sigma_trans^2 I), the rotation block replaced by
// half of rotation_by_axis's residual covariance (in the camera's frame for the camera) when that is set.
Matrix6 CameraCovariance(const MotionPair& pair, const NoiseModel& noise);
Matrix6 LidarCovariance(const MotionPair& pair, const NoiseModel& noise);
bool AllHaveCovariances(const std::vector<MotionPair>& pairs);

Eigen::Vector3d RotationResidual(const MotionPair& pair, const Eigen::Matrix3d& R);
Eigen::Vector3d TranslationResidual(const MotionPair& pair, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                    double scale = 1.0);
// [r_rot ; r_t] of a scaled pair (scale 1).
Vector6 PairResidual(const MotionPair& pair, const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

// Jacobians of [r_rot ; r_t] with respect to the perturbations of A and of B (MotionPair's model), at (R, t):
//   d r_rot = R^T d_rot_a - d_rot_b,   d r_t = -R_a [t]x d_rot_a + d_t_a - R d_t_b.
Matrix6 JacobianWrtA(const MotionPair& pair, const Eigen::Matrix3d& R, const Eigen::Vector3d& t);
Matrix6 JacobianWrtB(const MotionPair& pair, const Eigen::Matrix3d& R);

// Covariance of [r_rot ; r_t]: J_A Sigma_A J_A^T + J_B Sigma_B J_B^T.
Matrix6 ResidualCovariance(const MotionPair& pair, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                           const NoiseModel& noise);

// Jacobian of [r_rot ; r_t] with respect to the extrinsic perturbation [d_rot ; d_t], R -> R Exp(d_rot):
//   [[I - R_b^T, 0], [R [t_b]x, R_a - I]].
Matrix6 JacobianWrtExtrinsic(const MotionPair& pair, const Eigen::Matrix3d& R);

// W such that W^T W = C^-1 (W = L^-1 for C = L L^T); C is regularised if not positive definite.
Eigen::MatrixXd WhiteningMatrix(const Eigen::MatrixXd& C);

// Pseudo-inverse of a symmetric positive semi-definite information matrix over its eigenvalues above
// 1e-12 x the largest, or with `square_root` its square root (H^-1/2); the eigenvectors left out (null
// directions) are appended to *nulls when given.
Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& info, std::vector<Eigen::VectorXd>* nulls = nullptr,
                              bool square_root = false);

}  // namespace fusecal::handeye
