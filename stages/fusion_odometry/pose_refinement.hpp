// Step 5 of the fusion odometry (paper III-B-1): refine the camera motion by minimising the angular error
//   E(A) = sum_k rho( |v'_k x Proj(A^-1 p_ci,k)|^2 ),
// the paper's |v'_j x Proj(R_a (R p_j + t) + t_a)| with (R, t) = X (p_ci = X p_li) and (R_a, t_a) = A^-1
// (point into camera j); Proj normalises onto the unit sphere, v'_k is the unit bearing of the tracked pixel
// in image j, |v x u| = sin(angle). rho: Cauchy or Huber (robust loss: tracks on vehicles moving with the
// car must not pull the pose). A is parametrised by a unit quaternion on its manifold and a translation.
//
// Rounds: refine on the current inliers, re-classify every correspondence by its angle under the refined
// pose (at most max_residual_px, in front of camera j), refine again; so tracks whose residual under the
// final pose is large are rejected.
#pragma once

#include <string>
#include <vector>

#include "stages/foundation/se3.hpp"
#include "stages/fusion_odometry/settings.hpp"
#include "stages/fusion_odometry/types.hpp"

namespace fusecal::fusion_odometry {

struct RefinementResult {
  bool ok = false;
  Isometry3 T_ci_cj = Isometry3::Identity();
  std::vector<int> inliers;  // indices into the correspondences
  int iterations = 0;        // Ceres iterations, all rounds
  double rms_rad = 0.0;      // over the inliers
  double median_rad = 0.0;
  // Over [d_rot; d_t] with R = R_hat Exp(d_rot), t = t_hat + d_t (handeye_types.hpp, MotionPair::cov_A).
  bool covariance_valid = false;
  Matrix6 covariance = Matrix6::Identity();
  std::string message;  // why not ok
};

// initial_inliers: the correspondences the first round uses (e.g. the RANSAC inliers).
RefinementResult RefinePose(const Correspondences& correspondences, const Isometry3& initial_T_ci_cj,
                            const std::vector<int>& initial_inliers, double pixel_angle_rad,
                            const RefinementSettings& settings);

// Covariance of A over [d_rot; d_t] (model above) from the residuals of the given correspondences:
// sigma^2 (J^T J)^-1, sigma^2 = sum |r|^2 / (2 n - 6). False when J^T J is singular or n < 4.
bool PoseCovariance(const Correspondences& correspondences, const std::vector<int>& inliers, const Isometry3& T_ci_cj,
                    Matrix6* covariance);

}  // namespace fusecal::fusion_odometry
