// Hand-eye solver: T_camera_lidar from pairs of camera and LiDAR motions (A X = X B).
//
// Neither entry point throws: bad settings or inputs give status "failed" or rejected pairs with a reason.
#pragma once

#include <vector>

#include "stages/handeye/handeye_types.hpp"

namespace fusecal {

// Initial, scaleless solve (paper: initial extrinsic; docs/design.md section 1 step 3).
//  1. Rotation from the rotation axes, k_a = R k_b, by SVD (Kabsch on rotation vectors, i.e. weighted by the
//     rotation angles), then refined over sum_i |Log(R_b^T R^T R_a R)|^2, a geodesic form of the paper's
//     sum_i |R_a R - R R_b|.
//  2. t and one scale per motion by linear least squares:  (R_a - I) t + s_i t_a = R t_b.
// Camera translations may have any length (unit directions typically); camera_scaled is ignored.
// `initial`, when given, is a candidate starting rotation and fixes what the data leaves unobservable.
HandEyeResult SolveScaleless(const std::vector<MotionPair>& pairs, const HandEyeSettings& settings = {},
                             const Isometry3* initial = nullptr);

// Scaled solve (metric camera motions, e.g. from sensor fusion odometry; docs/design.md section 1 step 5).
// Rotation as above (or from `initial`), t linearly with scales fixed to 1, then a joint nonlinear
// refinement of R and t over all pairs, weighted by the covariances when given, with a robust loss while
// outliers are rejected. Pairs with camera_scaled == false are rejected.
HandEyeResult SolveScaled(const std::vector<MotionPair>& pairs, const HandEyeSettings& settings = {},
                          const Isometry3* initial = nullptr);

}  // namespace fusecal
