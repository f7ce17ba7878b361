// Linear rotation estimates (paper: initial extrinsic, rotation part).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "stages/handeye/handeye_types.hpp"

namespace fusecal::handeye {

// Rotation axes satisfy k_a = R k_b (R_a = R R_b R^T). Solves the weighted Wahba problem
//   max_R sum_i theta_a,i theta_b,i k_a,i^T R k_b,i
// by SVD of H = sum_i omega_a,i omega_b,i^T (Kabsch on rotation vectors omega = theta k): the weights
// theta_a theta_b down-weight small rotations, whose axes are ill defined. A second pass flips the sign of
// camera axes that disagree with the first estimate (the axis sign of rotations near pi is ambiguous).
// With all axes parallel the result maps the axis correctly; the rotation about it is arbitrary.
Eigen::Matrix3d RotationFromAxes(const std::vector<MotionPair>& pairs);

// The rotation closest to R_init with R k_b = k_a (R_init followed by the smallest rotation taking
// R_init k_b onto k_a).
Eigen::Matrix3d AlignAxis(const Eigen::Matrix3d& R_init, const Eigen::Vector3d& k_b, const Eigen::Vector3d& k_a);

// Motions all about one axis k_b (LiDAR frame) leave the rotation about that axis unobserved by the
// rotations. With metric translations it is observed through  R_a t + t_a = R t_b + t : writing
// R = R0 Exp(alpha k_b) with R0 k_b = k_a and R0 Exp(alpha k_b) t_b = R0 (c P t_b + s k_b x t_b + k_b k_b^T t_b),
// P = I - k_b k_b^T, c = cos alpha, s = sin alpha, the equations are linear in [t, c, s]:
//   (R_a - I) t - c R0 P t_b - s R0 (k_b x t_b) = R0 k_b k_b^T t_b - t_a.
// Returns false (R unchanged) when (c, s) is not determined, e.g. all screw axes on one line.
bool RotationAboutCommonAxis(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R0,
                             const Eigen::Vector3d& k_b, Eigen::Matrix3d* R);

}  // namespace fusecal::handeye
