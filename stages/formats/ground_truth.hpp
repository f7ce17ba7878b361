// Reading the reference extrinsic from a log's GROUND_TRUTH channel or from a result file.
//
// A log holds one GROUND_TRUTH message per extrinsic: each T_camera_lidar holds from the message's utime
// until the next message's (a camera moved on its mount mid-session gives more than one; see
// lcmtypes/fusecal/ground_truth_t.lcm). The stations are the same in every message.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fusecal/ground_truth_t.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal {

// The last GROUND_TRUTH message of a log (the extrinsic in force at its end), or nullopt when it has
// none. Throws LogError when the file is not a log.
std::optional<ground_truth_t> ReadGroundTruth(const std::string& log_path);

// Every GROUND_TRUTH message of a log, in log order (empty when it has none). Throws LogError when the
// file is not a log.
std::vector<ground_truth_t> ReadGroundTruths(const std::string& log_path);

// The index (into station_id, T_world_lidar, ...) of the truth's still interval that holds `utime`, or
// nullopt: detected stations are matched to the truth by time, not by id (a detector may number them
// differently, or miss one).
std::optional<int> TruthStationAt(const ground_truth_t& truth, int64_t utime);

// An extrinsic of the truth and the utime from which it holds.
struct TruthExtrinsic {
  Isometry3 T_camera_lidar = Isometry3::Identity();
  int64_t from_utime = 0;
};

// The message's extrinsic, as written: throws std::runtime_error naming the message's utime when it is
// not a rigid transform (non-finite, all zeros, a rotation block that is not orthonormal with determinant
// 1 within 1e-4, or a last row other than 0 0 0 1), where FromRowMajor alone would make a rotation of it.
TruthExtrinsic CheckedTruthExtrinsic(const ground_truth_t& truth);

// The extrinsic in force at `utime`: that of the message with the latest utime at or before it (the
// earliest message when `utime` precedes them all). Every message's extrinsic is checked as by
// CheckedTruthExtrinsic. Throws std::runtime_error when `truths` is empty.
TruthExtrinsic TruthExtrinsicAt(const std::vector<ground_truth_t>& truths, int64_t utime);
// The one in force at the end of the log: the message with the latest utime.
TruthExtrinsic TruthExtrinsicAtEnd(const std::vector<ground_truth_t>& truths);

// The reference for `fusecal evaluate`: from a result YAML (.yaml/.yml; no from_utime, and `at_utime`
// is refused), or from a log's GROUND_TRUTH, the extrinsic in force at `at_utime`, by default at the
// log's end. Throws std::runtime_error with the reason when there is none or it is not rigid.
struct ReferenceExtrinsic {
  Isometry3 T_camera_lidar = Isometry3::Identity();
  std::optional<int64_t> from_utime;
};
// `camera`: that camera's on a rig of several (GROUND_TRUTH whose camera is named so; T_<camera>_lidar of a
// rig's result file).
ReferenceExtrinsic ReadReference(const std::string& log_or_yaml, std::optional<int64_t> at_utime = std::nullopt,
                                 const std::string& camera = "");

// ReadReference(log_or_yaml).T_camera_lidar.
Isometry3 ReadReferenceExtrinsic(const std::string& log_or_yaml);

}  // namespace fusecal
