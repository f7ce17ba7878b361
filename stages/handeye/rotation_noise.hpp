// Rotation noise by direction (internal to the solver). A spinning LiDAR's registration does not pin all
// rotations alike: about its spin axis walls fix it, about the horizontal axes only the floor, the ceiling
// and the beam pattern do. One isotropic sigma pooled over the axes then overstates the precision of one
// axis of the extrinsic and understates another's.
//
// The hand-eye rotation residual r = Log(R_b^T R^T R_a R) of a motion about the axis k (LiDAR frame) splits
// into its part along k, the error of the rotation angle, which the extrinsic cannot change (I - R_b^T
// has k in its null space, paper Eq. (2)), and the two components across k, which determine the
// extrinsic. How large those are depends on the kind of motion, not only on the direction: a LiDAR turning
// about its spin axis errs about x by more than one tilting about y does. The model, for the residual of
// both sensors together, in the LiDAR frame, for a motion whose axis k lies mostly along the axis c:
//   Cov(r) = P diag(v_xc, v_yc, v_zc) P + v_axial k k^T,     P = I - k k^T,
// with v_jc estimated from the components across the axes of the motions of class c (a turn about z
// informs v_xz and v_yz), pooled with the isotropic estimate as a prior worth `prior_components`
// components (a class without motions takes the pooled value), and v_axial from the components along the
// axes.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "stages/handeye/handeye_types.hpp"

namespace fusecal::handeye {

struct RotationNoiseByAxis {
  // Column c: v_xc, v_yc, v_zc (rad^2, LiDAR frame) of the motions turning mostly about the axis c.
  Eigen::Matrix3d across_variance = Eigen::Matrix3d::Zero();
  double axial_variance = 0.0;                                   // v_axial (rad^2)
  Eigen::Matrix3d R_camera_lidar = Eigen::Matrix3d::Identity();  // maps the camera's share into its frame
};

// The residual covariance of the rotation of `pair` (both sensors together, LiDAR frame).
Eigen::Matrix3d RotationResidualCovariance(const MotionPair& pair, const RotationNoiseByAxis& noise);

// From the rotation residuals at R of the pairs without covariances; nullopt with fewer than 3 of them.
// Variances are corrected for the 3 estimated rotation parameters and kept above `floor_variance`.
std::optional<RotationNoiseByAxis> EstimateRotationNoiseByAxis(const std::vector<MotionPair>& pairs,
                                                               const Eigen::Matrix3d& R, double floor_variance,
                                                               double prior_components = 2.0);

}  // namespace fusecal::handeye
