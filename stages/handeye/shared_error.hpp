// Errors that every motion of one sensor makes alike. A camera whose focal length is off, a LiDAR whose
// ranges are scaled, a front end that makes every motion a little short: all pairs err the same way, so
// no residual shows it (the extrinsic absorbs it) and a covariance from the residuals leaves it out.
// They are added as consider parameters (uncertain, not estimated): per sensor, one unknown linear map of
// the motion, the same for all its motions,
//   d_rot_i = G w_i,   d_t_i = H t_i + K w_i      (w_i, t_i: motion i's rotation vector and translation,
//                                                  d_*: MotionPair's perturbation model),
// with independent zero-mean entries of G (rad/rad), H (m/m) and K (m/rad) of the given standard
// deviations, and a common length scale s (H + s I: every translation long or short alike, as a camera's
// metric depth that errs by one factor makes them). Through the linearised least squares (hand-eye
// residuals of pair_model.hpp),
//   d_x = -(sum J_x^T W J_x)^-1 sum J_x^T W J_m d_m_i,
// their covariance over [d_rot ; t] is
//   C_shared = sum over maps M and their 3 input components k of sigma_M^2 B_k B_k^T,
//   B_k = (sum J_x^T W J_x)^-1 sum_i u_ik J_x,i^T W_i J_m,i^M      (u = w for G and K, t for H),
// since E[d_i d_j^T] = sigma^2 (u_i . u_j) I for a map with independent entries; the scale adds
// sigma_s^2 b b^T, b = (sum J_x^T W J_x)^-1 sum_i J_x,i^T W_i J_t,i t_i.
#pragma once

#include <vector>

#include "stages/handeye/handeye_types.hpp"
#include "stages/handeye/pair_model.hpp"

namespace fusecal::handeye {

// C_shared for scaled pairs at (R, t), weighted as the final solve (`noise` for pairs without covariances).
Matrix6 SharedErrorCovariance(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                              const NoiseModel& noise, const SharedErrors& camera, const SharedErrors& lidar);

}  // namespace fusecal::handeye
