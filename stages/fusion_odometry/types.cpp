#include "stages/fusion_odometry/types.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace fusecal::fusion_odometry {

double PixelAngleRad(const CameraModel& camera) {
  const Eigen::Vector2d centre((camera.width() - 1) / 2.0, (camera.height() - 1) / 2.0);
  const Eigen::Vector3d a = camera.Unproject(centre - Eigen::Vector2d(0.5, 0.0));
  const Eigen::Vector3d b = camera.Unproject(centre + Eigen::Vector2d(0.5, 0.0));
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

double BearingAngle(const Eigen::Vector3d& v_j, const Eigen::Vector3d& p_cj) {
  return std::atan2(v_j.cross(p_cj).norm(), v_j.dot(p_cj));
}

}  // namespace fusecal::fusion_odometry
