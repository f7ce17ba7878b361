// A textured box room rendered by ray casting through a CameraModel: image pairs with a known relative pose
// for the camera front end's tests and benchmark.
//
// World frame axes as the camera's (x right, y down, z forward); the room spans
// [-3, 3] x [-1.5, 1.5] x [-4, 4] m. Each of the six faces carries a photograph (camera_frontend_data/README.md),
// flipped differently so that no two faces look alike.
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <string>

#include "foundation/camera_model.hpp"
#include "foundation/se3.hpp"

namespace fusecal::test {

class SyntheticRoom {
 public:
  // Loads the photographs from data_dir; throws std::runtime_error when one is missing.
  explicit SyntheticRoom(const std::string& data_dir);

  // Grey 8-bit image seen by `camera` at pose T_world_camera: supersample x supersample rays per pixel,
  // plus Gaussian noise of noise_sigma grey levels (seeded, so reproducible).
  cv::Mat Render(const CameraModel& camera, const Isometry3& T_world_camera, int supersample = 2,
                 double noise_sigma = 1.5, unsigned seed = 1) const;

  // Grey value seen along a ray from inside the room.
  float Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;

  Eigen::Vector3d min_corner{-3.0, -1.5, -4.0};
  Eigen::Vector3d max_corner{3.0, 1.5, 4.0};

 private:
  std::array<cv::Mat, 6> textures_;  // CV_32F; faces -x, +x, -y, +y, -z, +z
};

// The motion A = T_ci_cj between two camera poses in the world.
inline Isometry3 RelativeMotion(const Isometry3& T_world_ci, const Isometry3& T_world_cj) {
  return T_world_ci.inverse() * T_world_cj;
}

}  // namespace fusecal::test
