// Bearing-vector geometry shared by the front end's steps.
//
// Motion convention (docs/design.md section 2): the camera motion is A = T_ci_cj, the pose of camera j in the
// frame of camera i, p_i = R p_j + t. For a correspondence with unit bearings f_i (image i) and f_j (image j)
// of the same point, f_i, R f_j and t lie in one plane, the epipolar plane: f_i . (t x R f_j) = 0.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "stages/foundation/camera_model.hpp"

namespace fusecal::camera_frontend {

using Bearings = std::vector<Eigen::Vector3d>;

// Angle subtended by one pixel at the image centre (radians); converts pixel thresholds to angles.
double PixelAngleRad(const CameraModel& camera);

// Signed angle (radians) between f_i and the epipolar plane spanned by t and R f_j, i.e.
// asin(f_i . n) with n = (t x R f_j) / |t x R f_j| (paper section III-A-1, the angular error that the
// refinement minimises). 0 when t and R f_j are parallel (the plane is undefined).
double EpipolarAngle(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Eigen::Vector3d& f_i,
                     const Eigen::Vector3d& f_j);

// Angle (radians) between f_i and R f_j: the residual of the rotation-only model (pure rotation, or
// points at infinity); over the inliers of a translating camera it measures the parallax.
double RotationOnlyAngle(const Eigen::Matrix3d& R, const Eigen::Vector3d& f_i, const Eigen::Vector3d& f_j);

// Median of the values (0 for none); the input is copied.
double Median(std::vector<double> values);

}  // namespace fusecal::camera_frontend
