// Linear translation (and per-motion scale) estimates (paper: initial extrinsic, translation part).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "stages/handeye/handeye_types.hpp"

namespace fusecal::handeye {

struct LinearTranslation {
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  // Normal matrix N of t with the scales marginalised (information up to 1/sigma^2); t = N^+ b.
  Eigen::Matrix3d N = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d N_pinv = Eigen::Matrix3d::Zero();
  std::vector<Eigen::Vector3d> null_directions;  // of N (t not determined along them)
  // dt/d(rotation perturbation), R -> R Exp(d): propagates the rotation covariance into t.
  Eigen::Matrix3d dt_drot = Eigen::Matrix3d::Zero();
  std::vector<double> scales;              // per pair (0 where t_a = 0); 1 when !with_scales
  std::vector<Eigen::Vector3d> residuals;  // (R_a - I) t + s_i t_a - R t_b per pair
  double residual_sum_squares = 0.0;
  int dof = 0;  // number of equations left after t and the scales
};

// Scaled (with_scales = false):     (R_a - I) t = R t_b - t_a            stacked, least squares.
// Scaleless (with_scales = true):   (R_a - I) t + s_i t_a = R t_b        with unknowns [t, s_1..s_n].
// The scales are eliminated per pair with the projection P_i = I - u u^T, u = t_a / |t_a|:
//   sum_i A_i^T P_i A_i t = sum_i A_i^T P_i R t_b,  A_i = R_a - I,   then s_i = u^T (R t_b - A_i t) / |t_a|,
// which is the same least-squares solution as the stacked system (Schur complement), and gives the
// covariance of t with the scales marginalised: sigma^2 N^-1.
// Along null directions of N, and along `fixed_directions` (unit, e.g. found unobservable), t takes the
// component of *t_prior (when given), else zero.
LinearTranslation SolveTranslation(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R, bool with_scales,
                                   const Eigen::Vector3d* t_prior = nullptr,
                                   const std::vector<Eigen::Vector3d>& fixed_directions = {});

// Pseudo-inverse of a symmetric 3x3 matrix; eigenvalues below rel_tol * max count as zero, their
// eigenvectors are appended to *null_directions.
Eigen::Matrix3d SymmetricPseudoInverse(const Eigen::Matrix3d& N, double rel_tol,
                                       std::vector<Eigen::Vector3d>* null_directions);

}  // namespace fusecal::handeye
