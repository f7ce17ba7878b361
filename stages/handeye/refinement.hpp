// Nonlinear refinement and covariance with Ceres (paper: nonlinear refinement of the rotation, and the
// joint re-estimation of X from scaled motions).
//
// The extrinsic rotation is parametrised as R = R0 Exp(d) with d a rotation vector (Ceres angle-axis) around
// the current estimate R0, t directly; the covariance is therefore over [d ; t], the model of HandEyeResult.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "stages/handeye/handeye_types.hpp"
#include "stages/handeye/pair_model.hpp"

namespace fusecal::handeye {

struct RefineOutput {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  bool usable = false;     // Ceres produced a usable solution
  bool converged = false;  // and terminated by convergence (not by the iteration limit)
  int iterations = 0;
  double final_cost = 0.0;  // 0.5 * sum of squared whitened residuals
  std::string message;
};

// Rotation only:  min_R sum_i rho(|W_i Log(R_b^T R^T R_a R)|^2), the geodesic form of the paper's
// sum_i |R_a R - R R_b|. W_i whitens with R^T Sigma_rot,a R + Sigma_rot,b (evaluated at R0).
RefineOutput RefineRotation(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R0, const NoiseModel& noise,
                            bool robust, const HandEyeSettings& settings);

// Joint:  min_{R,t} sum_i rho(|W_i [Log(R_b^T R^T R_a R) ; (R_a - I) t + t_a - R t_b]|^2), W_i from the
// first-order covariance of the 6-vector residual (evaluated at R0, t0), see ResidualCovariance.
RefineOutput RefinePose(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R0, const Eigen::Vector3d& t0,
                        const NoiseModel& noise, bool robust, const HandEyeSettings& settings);

// ceres::Covariance of the least-squares problems above (no loss), at the estimate itself (d = 0).
// Unscaled, i.e. (J^T J)^+ of the whitened Jacobian; directions with eigenvalue below 1e-14 * max are dropped.
// *cost receives 0.5 * sum of squared whitened residuals. False when Ceres fails.
bool RotationCovariance(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R, const NoiseModel& noise,
                        Eigen::Matrix3d* covariance, double* cost);
bool PoseCovariance(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                    const NoiseModel& noise, Matrix6* covariance, double* cost);

}  // namespace fusecal::handeye
