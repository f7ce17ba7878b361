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
#include "stages/formats/rig_file.hpp"

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

// A rig of several cameras, one transform per camera. A tree has one parent per frame, so the LiDAR
// (frames.child) is the parent and each camera's frame is named as the camera: ros-static-tf gives one
// line "x y z qx qy qz qw lidar <camera>" per camera and urdf one joint lidar -> <camera> each (the pose
// of the camera in the LiDAR frame, T_lidar_camera); kitti gives R_<camera> and T_<camera> per camera
// (p_camera = R p_lidar + T), json and opencv-yaml every T_<camera>_lidar with its std and the derived
// camera-to-camera transforms. Throws std::invalid_argument as ExportExtrinsic does.
std::string ExportRig(const RigResult& rig, const std::string& format, const ExportFrames& frames = {});

// Parses text produced by ExportExtrinsic (or written by hand in that format). Throws
// std::runtime_error saying what is missing or malformed.
Isometry3 ParseExportedExtrinsic(const std::string& text, const std::string& format);

}  // namespace fusecal
