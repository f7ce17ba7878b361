// Error of an estimated T_camera_lidar against a reference: geodesic rotation error and the
// translation difference (estimate minus reference, in the camera frame).
#pragma once

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

}  // namespace fusecal
