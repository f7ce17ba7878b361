// The camera file that commands take (`--camera CAMERA.yaml`):
//   model: pinhole | equirectangular
//   width: 1242
//   height: 375
//   fx: ..., fy: ..., cx: ..., cy: ...      (pinhole)
//   dist: [k1, k2, p1, p2, k3]              (pinhole, optional, OpenCV convention)
#pragma once

#include <string>

#include "stages/foundation/camera_model.hpp"

namespace fusecal {

// Throws ConfigError naming the file and key on unknown keys or invalid values.
CameraParams LoadCameraFile(const std::string& path);
CameraParams ParseCameraYaml(const std::string& text);

std::string CameraToYaml(const CameraParams& params);

}  // namespace fusecal
