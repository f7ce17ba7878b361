// Exporting T_camera_lidar into the formats users' stacks take, and reading each back.
//   kitti:         calib_velo_to_cam.txt style; R (row-major 9) and T (3) with p_camera = R p_lidar + T
//   ros-static-tf: static_transform_publisher arguments "x y z qx qy qz qw camera lidar"
//                  (the transform of the lidar frame in the camera frame)
//   json:          {"T_camera_lidar": [16 row-major], "translation_m", "rotation_quaternion_wxyz", ...}
//   opencv-yaml:   cv::FileStorage with T_camera_lidar (4x4), R, t, and std devs when known
//   urdf:          a robot with the two links and the fixed joint parent -> child, <origin xyz rpy> the pose
//                  of the LiDAR frame in the camera frame (rpy about fixed x, y, z: R = Rz Ry Rx)
#pragma once

#include <string>
#include <vector>

#include "stages/formats/result_file.hpp"

namespace fusecal {

const std::vector<std::string>& ExportFormats();

// The frame names of ros-static-tf and urdf: the camera's (its optical frame: x right, y down, z forward)
// and the LiDAR's.
struct ExportFrames {
  std::string parent = "camera";
  std::string child = "lidar";
};

// Throws std::invalid_argument for an unknown format or a frame name that is empty or holds a space, a
// quote, '<', '>' or '&'.
std::string ExportExtrinsic(const CalibrationResult& result, const std::string& format,
                            const ExportFrames& frames = {});

// Parses text produced by ExportExtrinsic (or written by hand in that format). Throws
// std::runtime_error saying what is missing or malformed.
Isometry3 ParseExportedExtrinsic(const std::string& text, const std::string& format);

}  // namespace fusecal
