// Data passed between the steps of the sensor fusion odometry (paper section III-B-1).
//
// Conventions (docs/design.md section 2): X = T_camera_lidar maps LiDAR points into the camera frame; the camera
// motion is A = T_ci_cj, the pose of camera j in the frame of camera i: p_ci = A p_cj. A scan point of
// station i in camera frame i is p_ci = X p_li, and in camera j p_cj = A^-1 p_ci.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "stages/foundation/camera_model.hpp"

namespace fusecal::fusion_odometry {

// A scan point that camera i sees.
struct ScanPoint {
  Eigen::Vector3d p_ci;     // camera frame i, metres
  Eigen::Vector2d pixel_i;  // its projection into image i
  double range = 0.0;       // |p_ci|
  int index = -1;           // index in the scan
};

// A 2D-3D correspondence: a scan point and where it was tracked to in image j.
struct Correspondence {
  Eigen::Vector3d p_ci;
  Eigen::Vector2d pixel_i;
  Eigen::Vector2d pixel_j;
  Eigen::Vector3d bearing_j;  // unit bearing of pixel_j in camera frame j (v'_j of the paper)
  int index = -1;             // index in the scan
};

using Correspondences = std::vector<Correspondence>;

// Angle subtended by one pixel at the image centre (radians); converts pixel thresholds to angles.
double PixelAngleRad(const CameraModel& camera);

// Angle (radians) between the bearing v_j and the point p_cj seen from camera j.
double BearingAngle(const Eigen::Vector3d& v_j, const Eigen::Vector3d& p_cj);

}  // namespace fusecal::fusion_odometry
