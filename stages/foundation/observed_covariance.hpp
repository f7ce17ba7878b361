// The uncertainty of what the motions observe. Along an unobservable direction the hand-eye solver adds a
// huge variance (kUnobservableVariance), and since that direction is seldom along an axis it shows in all
// three per-axis standard deviations. Projected out, the rest is the honest uncertainty of the observed
// part: for motions about one vertical axis, the rotation about the two horizontal axes.
#pragma once

#include <Eigen/Core>

#include "stages/foundation/se3.hpp"

namespace fusecal {

struct ObservedUncertainty {
  Matrix6 covariance = Matrix6::Zero();  // [rotation (rad, LiDAR axes) ; translation (m, camera axes)]
  Eigen::Vector3d rotation_std_deg = Eigen::Vector3d::Zero();  // per axis, of the projected covariance
  Eigen::Vector3d translation_std_m = Eigen::Vector3d::Zero();
  double max_rotation_std_deg = 0.0;  // the largest over all directions of the observed part
  double max_translation_std_m = 0.0;
  bool rotation_projected = false;     // the rotation about the direction was unobserved
  bool translation_projected = false;  // the translation along it was unobserved
};

// `covariance` in the result's model (R = R_hat Exp(d_rot): d_rot about LiDAR axes; t = t_hat + d_t:
// camera axes); `direction`: the unobservable direction, camera frame (zero: nothing is projected).
// The rotation about it (R^T direction in d_rot coordinates) and the translation along it are projected
// out where their variance is at least kUnobservedVariance.
ObservedUncertainty ObservedPart(const Matrix6& covariance, const Eigen::Matrix3d& R, const Eigen::Vector3d& direction);

// Variance from which a direction counts as unobserved (the solver adds 1e6 rad^2 or m^2 there).
inline constexpr double kUnobservedVariance = 1e3;

}  // namespace fusecal
