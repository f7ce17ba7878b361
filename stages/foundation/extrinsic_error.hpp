// Error of an estimated T_camera_lidar against a reference: geodesic rotation error and the
// translation difference (estimate minus reference, in the camera frame).
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "stages/foundation/se3.hpp"

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
  e.direction_deg =
      std::atan2(from_estimate.cross(from_reference).norm(), from_estimate.dot(from_reference)) * 180.0 / M_PI;
  const Eigen::Vector3d dt = estimate.translation() - reference.translation();
  e.translation_perpendicular_m = dt - d * d.dot(dt);
  return e;
}

// The size of a change from `before` to `after` (rotation angle, translation distance) and its standard
// deviation along the change, from the covariances of both (model of HandEyeResult: rotation about LiDAR
// axes, translation in camera axes); along the largest axis when there was no change.
struct ExtrinsicChangeSize {
  double rotation_deg = 0, rotation_std_deg = 0;
  double translation_m = 0, translation_std_m = 0;
};

inline ExtrinsicChangeSize SizeOfChange(const Isometry3& before, const Matrix6& covariance_before,
                                        const Isometry3& after, const Matrix6& covariance_after) {
  const Matrix6 C = covariance_before + covariance_after;
  const Eigen::AngleAxisd turn(before.linear().transpose() * after.linear());
  const Eigen::Vector3d dt = after.translation() - before.translation();
  const auto std_along = [](const Eigen::Matrix3d& block, const Eigen::Vector3d& v) {
    if (v.norm() < 1e-12) return std::sqrt(std::max(0.0, block.diagonal().maxCoeff()));
    const Eigen::Vector3d u = v.normalized();
    return std::sqrt(std::max(0.0, u.dot(block * u)));
  };
  ExtrinsicChangeSize s;
  s.rotation_deg = std::abs(turn.angle()) * 180.0 / M_PI;
  s.rotation_std_deg = std_along(C.topLeftCorner<3, 3>(), turn.axis() * turn.angle()) * 180.0 / M_PI;
  s.translation_m = dt.norm();
  s.translation_std_m = std_along(C.bottomRightCorner<3, 3>(), dt);
  return s;
}

}  // namespace fusecal
