// A motion pair of a rig whose camera may move on its mount during the motion, for hand-eye tests.
#pragma once

#include <cmath>
#include <random>

#include "stages/foundation/se3.hpp"
#include "stages/handeye/handeye_types.hpp"

namespace fusecal {

// A pair whose LiDAR turns by angle_deg about `axis` (LiDAR frame) and moves by `shift`, with the camera at
// X_i on the mount before the motion and X_j after it: A = X_i B X_j^-1 (A X = X B when they are equal).
// The camera motion is metric, with 0.01 deg (as the 5-point solver) and 0.3 mm of noise per axis.
inline MotionPair Turn(int i, const Eigen::Vector3d& axis, double angle_deg, const Eigen::Vector3d& shift,
                       const Isometry3& X_i, const Isometry3& X_j, std::mt19937& rng) {
  MotionPair p;
  p.station_i = i;
  p.station_j = i + 1;
  p.B = Isometry3::Identity();
  p.B.linear() = Eigen::AngleAxisd(angle_deg * M_PI / 180, axis.normalized()).toRotationMatrix();
  p.B.translation() = shift;
  p.A = X_i * p.B * X_j.inverse();
  std::normal_distribution<double> noise(0.0, 1.0);
  const Eigen::Vector3d rot_noise(noise(rng), noise(rng), noise(rng));
  p.A.linear() = p.A.linear() * ExpSO3(0.01 * M_PI / 180 * rot_noise);
  p.A.translation() += 0.0003 * Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  p.camera_scaled = true;
  return p;
}

}  // namespace fusecal
