// Pictures that show whether an extrinsic is right: LiDAR points projected into the camera image,
// coloured by depth, and the paper's checkerboard interleave of camera image and LiDAR image.
#pragma once

#include <opencv2/core.hpp>

#include "stages/foundation/camera_model.hpp"
#include "stages/foundation/point_cloud.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal {

// Per-pixel nearest depth (metres, 0 = no point) and intensity of the scan seen from the camera.
struct ProjectedScan {
  cv::Mat depth;      // CV_32F
  cv::Mat intensity;  // CV_32F, scan intensity (0 where none)
};
ProjectedScan ProjectScan(const PointCloud& cloud, const CameraModel& camera, const Isometry3& T_camera_lidar);

// The camera image with the projected points drawn as dots coloured by depth (near red, far blue).
cv::Mat RenderDepthOverlay(const cv::Mat& image, const PointCloud& cloud, const CameraModel& camera,
                           const Isometry3& T_camera_lidar, double max_depth_m = 40.0);

// Camera image and LiDAR intensity image interleaved like a checkerboard (the paper's check):
// misalignment shows as broken lines at the square borders.
cv::Mat RenderCheckerboard(const cv::Mat& image, const PointCloud& cloud, const CameraModel& camera,
                           const Isometry3& T_camera_lidar, int square_px = 64);

// Mean distance (pixels) from LiDAR depth discontinuities to the nearest image edge (Canny), over
// depth-edge pixels. Small when the extrinsic is right; grows when it is off.
double DepthEdgeToImageEdgeDistance(const cv::Mat& image, const PointCloud& cloud, const CameraModel& camera,
                                    const Isometry3& T_camera_lidar);

}  // namespace fusecal
