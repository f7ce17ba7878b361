// Nonlinear refinement of the relative pose (paper section III-A-1: after RANSAC the pose is refined by
// minimising the angular error with respect to the epipolar plane).
//
// For each inlier, the residual is the angle between f_i and the epipolar plane spanned by t and R f_j
// (bearings.hpp, EpipolarAngle), under a Cauchy loss. R is a quaternion on ceres::EigenQuaternionManifold,
// t lives on the unit sphere (ceres::SphereManifold<3>): translation has no scale.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "stages/camera_frontend/bearings.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal::camera_frontend {

struct EpipolarRefinement {
  bool ok = false;         // the solver ran and produced a finite motion
  bool converged = false;  // Ceres reported convergence (not the iteration limit)
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // R_ci_cj
  Eigen::Vector3d t = Eigen::Vector3d::UnitZ();     // unit direction of t_ci_cj
  // 6x6 over [d_rot (rad); d_t], with the perturbation model of handeye_types.hpp:
  //   R = R_hat * Exp(d_rot) (right perturbation, rotation vector in frame j), t = t_hat + d_t (frame i).
  // The translation block is that of the unit direction: rank 2, tangent to the sphere at t. Scaled by the
  // residual variance sigma^2 = (1.4826 * median |residual|)^2 (Ceres' covariance assumes unit variance).
  // Filled when requested and computable (covariance_ok).
  bool covariance_ok = false;
  Matrix6 covariance = Matrix6::Identity();
};

EpipolarRefinement RefineEpipolar(const Bearings& f_i, const Bearings& f_j, const std::vector<int>& inliers,
                                  const Eigen::Matrix3d& R0, const Eigen::Vector3d& t0, double loss_scale_rad,
                                  int max_iterations, bool compute_covariance);

}  // namespace fusecal::camera_frontend
