// Reading the reference extrinsic from a log's GROUND_TRUTH channel or from a result file.
#pragma once

#include <optional>
#include <string>

#include "foundation/se3.hpp"
#include "fusecal/ground_truth_t.hpp"

namespace fusecal {

// The last GROUND_TRUTH message of a log, or nullopt when it has none. Throws LogError when the file
// is not a log.
std::optional<ground_truth_t> ReadGroundTruth(const std::string& log_path);

// The index (into station_id, T_world_lidar, ...) of the truth's still interval that holds `utime`, or
// nullopt: detected stations are matched to the truth by time, not by id (a detector may number them
// differently, or miss one).
std::optional<int> TruthStationAt(const ground_truth_t& truth, int64_t utime);

// The reference T_camera_lidar from a log (GROUND_TRUTH) or a result YAML (.yaml/.yml). Throws
// std::runtime_error with the reason when there is none.
Isometry3 ReadReferenceExtrinsic(const std::string& log_or_yaml);

}  // namespace fusecal
