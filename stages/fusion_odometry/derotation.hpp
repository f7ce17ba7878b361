// Rotation compensation before tracking. KLT follows a translating window; a turn or tilt of the camera
// between stations also rotates and shears the image patches (strongly so in a panorama, where a tilt
// bends the rows), which biases the tracked position. Image j is therefore resampled as seen from camera
// j's position with camera i's orientation (the predicted rotation R_a of A = T_ci_cj removed), so that
// what KLT has to follow is the parallax only:
//   derotated(x') = image_j( map(x') ),   map(x') ~ Project( R_a^T Unproject(x') ).
// The map is exact on a grid and bilinear in between; a pixel x' tracked in the derotated image lies at
// map(x') in image j, the map actually sampled, so the grid's interpolation error never reaches the bearing
// (on a 1024 px panorama tilted by 13 deg an 8 px grid is off by up to 0.18 px within 60 deg of the horizon,
// which made every simulated tilt 45 urad too large when the bearing was taken as R_a^T Unproject(x')).
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "stages/foundation/camera_model.hpp"

namespace fusecal::fusion_odometry {

// Where each pixel of the derotated image is sampled from in image j. Evaluated exactly on a grid every
// grid_step pixels and interpolated bilinearly in between (the map is smooth away from the poles of a
// panorama); columns of a panorama wrap. Directions camera j cannot see lie far outside image j.
class DerotationMap {
 public:
  DerotationMap(const CameraModel& camera, const Eigen::Matrix3d& R_ci_cj, int grid_step = 8);

  // The pixel of image j that derotated pixel (x, y) (sub-pixel) is sampled from; a panorama's column in
  // [0, width).
  Eigen::Vector2d SourcePixel(double x, double y) const;

  // grey_j (8-bit grey of the camera's size) resampled; directions camera j cannot see replicate its border.
  cv::Mat Resample(const cv::Mat& grey_j) const;

 private:
  // The bilinear interpolation of the grid at (x, y), panorama columns not yet wrapped.
  Eigen::Vector2f Interpolate(float x, float y) const;

  int width_ = 0, height_ = 0, step_ = 1, grid_w_ = 0, grid_h_ = 0;
  bool wrap_ = false;
  std::vector<float> gx_, gy_;
};

// DerotationMap(camera, R_ci_cj, grid_step).Resample(grey_j).
cv::Mat DerotateImage(const cv::Mat& grey_j, const CameraModel& camera, const Eigen::Matrix3d& R_ci_cj,
                      int grid_step = 8);

}  // namespace fusecal::fusion_odometry
