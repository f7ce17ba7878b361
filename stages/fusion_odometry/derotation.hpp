// Rotation compensation before tracking. KLT follows a translating window; a turn or tilt of the camera
// between stations also rotates and shears the image patches (strongly so in a panorama, where a tilt
// bends the rows), which biases the tracked position. Image j is therefore resampled as seen from camera
// j's position with camera i's orientation (the predicted rotation R_a of A = T_ci_cj removed), so that
// what KLT has to follow is the parallax only:
//   derotated(x') = image_j( Project( R_a^T Unproject(x') ) ),
// and a pixel x' tracked in the derotated image is the bearing v'_j = R_a^T Unproject(x') of camera j.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "foundation/camera_model.hpp"

namespace fusecal::fusion_odometry {

// grey_j: 8-bit grey of the camera's size. The map is evaluated exactly on a grid every grid_step pixels
// and interpolated bilinearly in between (the map is smooth away from the poles of a panorama); columns
// of a panorama wrap. Directions camera j cannot see are filled by replicating its border.
cv::Mat DerotateImage(const cv::Mat& grey_j, const CameraModel& camera, const Eigen::Matrix3d& R_ci_cj,
                      int grid_step = 8);

}  // namespace fusecal::fusion_odometry
