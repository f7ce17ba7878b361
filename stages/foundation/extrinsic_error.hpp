// Error of an estimated T_camera_lidar against a reference: geodesic rotation error and the
// translation difference (estimate minus reference, in the camera frame).
#pragma once

#include <cmath>

#include "foundation/se3.hpp"

namespace fusecal {

struct ExtrinsicError {
  double rotation_deg = 0;
  double translation_m = 0;
  Eigen::Vector3d translation_xyz_m = Eigen::Vector3d::Zero();
};

inline ExtrinsicError CompareExtrinsics(const Isometry3& estimate, const Isometry3& reference) {
  ExtrinsicError e;
  e.rotation_deg = RotationErrorDeg(estimate.linear(), reference.linear());
  e.translation_xyz_m = estimate.translation() - reference.translation();
  e.translation_m = e.translation_xyz_m.norm();
  return e;
}

// What can be compared when the motions left `direction` (camera frame, unit) unobserved: the angle
// between the LiDAR-frame directions that estimate and reference map onto it (the rotation about it is
// not counted), and the translation error perpendicular to it (meaningful when only t along it is
// unobserved).
struct ObservableError {
  double direction_deg = 0;
  Eigen::Vector3d translation_perpendicular_m = Eigen::Vector3d::Zero();
};

inline ObservableError CompareObservablePart(const Isometry3& estimate, const Isometry3& reference,
                                             const Eigen::Vector3d& direction) {
  const Eigen::Vector3d d = direction.normalized();
  const Eigen::Vector3d from_estimate = estimate.linear().transpose() * d;
  const Eigen::Vector3d from_reference = reference.linear().transpose() * d;
  ObservableError e;
  e.direction_deg = std::atan2(from_estimate.cross(from_reference).norm(), from_estimate.dot(from_reference)) *
                    180.0 / M_PI;
  const Eigen::Vector3d dt = estimate.translation() - reference.translation();
  e.translation_perpendicular_m = dt - d * d.dot(dt);
  return e;
}

}  // namespace fusecal
