// A rigid transform under one key of a YAML result file (the common result file, a rig's file).
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

#include "stages/foundation/se3.hpp"

namespace fusecal {

// root[key] as 16 numbers, row-major 4x4. Throws std::runtime_error naming `path` and `key` when it is
// missing, not 16 numbers, or not a rigid transform (rotation not orthonormal, non-finite, or last row
// not 0 0 0 1).
Isometry3 ReadYamlTransform(const YAML::Node& root, const std::string& key, const std::string& path);

}  // namespace fusecal
