// The common result file: YAML written by every command that outputs an extrinsic, read by every
// command that takes one (only `T_camera_lidar` is required when reading).
//
//   T_camera_lidar: [16 numbers, row-major]
//   translation_m: [x, y, z]
//   rotation_quaternion_wxyz: [w, x, y, z]
//   rotation_rpy_deg: [roll, pitch, yaw]          (R = Rz(yaw) Ry(pitch) Rx(roll))
//   std_dev_axes: which axes the std_dev are about (rotation: LiDAR axes, R = R_hat Exp(d); translation:
//                 camera axes)
//   std_dev: {rotation_deg: [3], translation_m: [3]}
//   std_dev_observed: {rotation_deg, translation_m, rotation_max_deg, translation_max_m, projected_out}
//                 when a direction is unobservable: the covariance with it projected out (ObservedPart)
//   status, observability, unobservable_direction (camera frame, when any), motions_used, motions_rejected,
//   residual_rms
//   changes: [{after_station, decided_at_station, rotation_deg, rotation_std_deg, translation_m,
//             translation_std_m, T_camera_lidar_before}]   (changes of the extrinsic the session detected;
//                 written when the writer watches for changes, empty when none)
//   initial: {...same keys...}                   (optional: the scaleless initial estimate)
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "stages/foundation/se3.hpp"

namespace fusecal {

// A change of the extrinsic mid-session (a sensor moved on its mount): between which stations, by how much.
struct ExtrinsicChangeRecord {
  int after_station = -1;       // the last station before the change
  int decided_at_station = -1;  // the station whose motion decided it
  double rotation_deg = 0, rotation_std_deg = 0;
  double translation_m = 0, translation_std_m = 0;
  Isometry3 T_before = Isometry3::Identity();  // the extrinsic in force before it
};

// A record of a change from the extrinsic before it to the one after (SizeOfChange, with both covariances).
ExtrinsicChangeRecord MakeChangeRecord(int after_station, int decided_at_station, const Isometry3& before,
                                       const Matrix6& covariance_before, const Isometry3& after,
                                       const Matrix6& covariance_after);

struct CalibrationResult {
  Isometry3 T_camera_lidar = Isometry3::Identity();
  std::optional<Matrix6> covariance;  // [rotation rad; translation m]
  std::string status = "unknown";
  std::string observability = "unknown";
  std::vector<std::string> motions_used;      // e.g. "3-4" (station ids)
  std::vector<std::string> motions_rejected;  // e.g. "5-6: rotation angles differ by 3.1 deg"
  double residual_rms = 0.0;
  // Camera frame, unit: the direction the motions leave unobserved (see observability), when there is one.
  std::optional<Eigen::Vector3d> unobservable_direction;
  std::map<std::string, std::string> extra;                   // further scalar facts (iterations, source, ...)
  std::optional<std::vector<ExtrinsicChangeRecord>> changes;  // set: written as `changes`, even when empty
};

// Standard deviations from a covariance: rotation in degrees, translation in metres.
Eigen::Vector3d RotationStdDevDeg(const Matrix6& covariance);
Eigen::Vector3d TranslationStdDevM(const Matrix6& covariance);

// Writes the result (and optionally the initial estimate under `initial`). Throws std::runtime_error
// naming the file when it cannot be written.
void WriteResultFile(const std::string& path, const CalibrationResult& result,
                     const CalibrationResult* initial = nullptr);
std::string ResultToYaml(const CalibrationResult& result, const CalibrationResult* initial = nullptr);

// Reads a result file; only T_camera_lidar is required. Throws std::runtime_error naming the file and
// the key when it is missing, not 16 finite numbers, or not a rigid transform.
CalibrationResult ReadResultFile(const std::string& path);

}  // namespace fusecal
