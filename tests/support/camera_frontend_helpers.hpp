// Cameras, poses and error measures shared by the camera front end tests and benchmark.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "camera_frontend/relative_pose.hpp"
#include "foundation/camera_model.hpp"
#include "foundation/se3.hpp"

namespace fusecal::test {

inline CameraParams PanoramaParams(int width) {
  CameraParams p;
  p.model = "equirectangular";
  p.width = width;
  p.height = width / 2;
  return p;
}

// Wide pinhole with noticeable barrel distortion.
inline CameraParams DistortedPinholeParams() {
  CameraParams p;
  p.model = "pinhole";
  p.width = 640;
  p.height = 480;
  p.fx = 380;
  p.fy = 381;
  p.cx = 321.3;
  p.cy = 238.2;
  p.dist = {-0.22, 0.06, 0.0008, -0.0005, -0.006};
  return p;
}

// KITTI image_02 after rectification: pinhole without distortion, from P_rect_02 of the snippet.
inline CameraParams KittiParams() {
  CameraParams p;
  p.model = "pinhole";
  p.width = 1242;
  p.height = 375;
  p.fx = 7.215377e+02;
  p.fy = 7.215377e+02;
  p.cx = 6.095593e+02;
  p.cy = 1.728540e+02;
  return p;
}

inline double Deg(double rad) { return rad * 180.0 / M_PI; }
inline double Rad(double deg) { return deg * M_PI / 180.0; }

inline Isometry3 Pose(const Eigen::Vector3d& position, double roll_deg, double pitch_deg, double yaw_deg) {
  return MakeIsometry(RotationFromRpy(Rad(roll_deg), Rad(pitch_deg), Rad(yaw_deg)), position);
}

inline double DirectionErrorDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return Deg(std::atan2(a.cross(b).norm(), a.dot(b)));
}

struct PoseErrors {
  double rotation_deg = 0;
  double translation_direction_deg = 0;
};

// Errors of an estimate against the true motion A = T_ci_cj.
inline PoseErrors Errors(const RelativePoseResult& r, const Isometry3& A_true) {
  PoseErrors e;
  e.rotation_deg = RotationErrorDeg(r.R, A_true.linear());
  e.translation_direction_deg = DirectionErrorDeg(r.t_unit, A_true.translation());
  return e;
}

}  // namespace fusecal::test
