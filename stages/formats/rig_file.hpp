// The result file of a rig of several cameras (extrinsic.yaml beside one folder per camera):
//
//   cameras: [front, left, ...]                   (the first is the reference of the camera-to-camera ones)
//   T_<camera>_lidar: [16 numbers, row-major]     per camera, as T_camera_lidar of the common result file
//   T_<camera>_lidar_std_dev: {rotation_deg: [3], translation_m: [3]}
//   T_<camera>_lidar_covariance: [36]             when known
//   T_<camera>_lidar_status: converged | ...      its loop's verdict
//   T_<camera>_lidar_file: <camera>/extrinsic.yaml   its whole result (the common result file)
//   T_<camera>_<first>: [16]                      derived: T_<camera>_lidar T_<first>_lidar^-1, for every
//   T_<camera>_<first>_std_dev, _covariance       camera after the first; its covariance from both loops'
//                                                 (taken as independent)
// Covariances everywhere: [rotation (rad^2, right perturbation R = R_hat Exp(d), about the source frame's
// axes: the LiDAR's, or camera <first>'s) ; translation (m^2, along the target camera's axes)].
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "stages/formats/result_file.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal {

struct RigCameraResult {
  std::string camera;
  Isometry3 T_camera_lidar = Isometry3::Identity();
  std::optional<Matrix6> covariance;
  std::string status = "unknown";
  std::string file;  // its common result file, relative to the rig file's folder
};

// T_<to>_<from>: camera `from` into camera `to`.
struct CameraToCamera {
  std::string to, from;
  Isometry3 T = Isometry3::Identity();
  std::optional<Matrix6> covariance;  // when both cameras' are known
};

struct RigResult {
  std::vector<RigCameraResult> cameras;
  std::vector<CameraToCamera> camera_to_camera;  // every camera after the first, from the first
};

// T_to_from = T_to_lidar T_from_lidar^-1, with the covariance of two independent estimates propagated
// to first order (the rotation's right perturbation about camera `from`'s axes, the translation along
// camera `to`'s).
CameraToCamera DeriveCameraToCamera(const RigCameraResult& to, const RigCameraResult& from);

// The rig result: each camera's, and every camera after the first from the first.
RigResult MakeRigResult(std::vector<RigCameraResult> cameras);

// Writes it (throws std::runtime_error naming the file when it cannot be written).
void WriteRigFile(const std::string& path, const RigResult& rig);
std::string RigToYaml(const RigResult& rig);

// Whether a result file is a rig's (it has `cameras`).
bool IsRigFile(const std::string& path);
// Reads one; throws std::runtime_error naming the file and the key when a camera's transform is missing
// or not rigid.
RigResult ReadRigFile(const std::string& path);

}  // namespace fusecal
