// Rotation-only model f_i = R f_j, for near-pure rotation (the essential matrix [t]x R is then undefined,
// any t fits, and only R can be trusted) and as the parallax measure that tells such motions apart.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "stages/camera_frontend/bearings.hpp"

namespace fusecal::camera_frontend {

struct RotationOnlyFit {
  bool ok = false;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // R_ci_cj
  double median_residual_rad = 0.0;                 // median angle between f_i and R f_j over the indices
  // Covariance of d_rot (R = R_hat Exp(d_rot)), scaled by the residual variance; see epipolar_refinement.hpp.
  bool covariance_ok = false;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();
};

// Closed form (Kabsch / Arun SVD of sum f_i (f_j)^T), then Ceres on the chord f_i - R f_j (about the angle)
// under a Cauchy loss of scale loss_scale_rad.
RotationOnlyFit FitRotationOnly(const Bearings& f_i, const Bearings& f_j, const std::vector<int>& indices,
                                double loss_scale_rad, int max_iterations, bool compute_covariance);

}  // namespace fusecal::camera_frontend
