#include "stages/camera_frontend/bearings.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace fusecal::camera_frontend {

double PixelAngleRad(const CameraModel& camera) {
  const Eigen::Vector2d centre((camera.width() - 1) / 2.0, (camera.height() - 1) / 2.0);
  const Eigen::Vector3d a = camera.Unproject(centre - Eigen::Vector2d(0.5, 0.0));
  const Eigen::Vector3d b = camera.Unproject(centre + Eigen::Vector2d(0.5, 0.0));
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

double EpipolarAngle(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Eigen::Vector3d& f_i,
                     const Eigen::Vector3d& f_j) {
  const Eigen::Vector3d n = t.cross(R * f_j);
  const double norm = n.norm();
  if (norm < 1e-12) return 0.0;
  return std::asin(std::clamp(f_i.dot(n) / norm, -1.0, 1.0));
}

double RotationOnlyAngle(const Eigen::Matrix3d& R, const Eigen::Vector3d& f_i, const Eigen::Vector3d& f_j) {
  const Eigen::Vector3d g = R * f_j;
  return std::atan2(f_i.cross(g).norm(), f_i.dot(g));
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

}  // namespace fusecal::camera_frontend
