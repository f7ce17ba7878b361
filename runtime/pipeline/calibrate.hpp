// `fusecal calibrate`: the five stage nodes in one process over memq://, fed from a log as fast as they
// take it (each event is fully processed before the next: nothing dropped, deterministic).
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "runtime/pipeline/outputs.hpp"
#include "runtime/pipeline/pipeline_config.hpp"
#include "runtime/pipeline/stage_table.hpp"

namespace fusecal {

struct CalibrateReport {
  CalibrationOutputs outputs;     // the one camera's; on a rig of several, the first camera's
  std::optional<RigOutputs> rig;  // a rig of several cameras: each camera's and the rig file
  StageCounters stage_counters;   // each stage's last STATUS counters (busy_s, ...; stages.csv)
  double span_s = 0;              // recording span: first to last event fed
  double outputs_seconds = 0;     // writing extrinsic.yaml, pictures, cloud
  double total_seconds = 0;
  int stations = 0;
};

// `progress` receives a one-line status after every station and extrinsic version. A log whose cameras
// have their own channels (CAMERA_IMAGE_front, ...) calibrates each of them when `config` names no cameras.
CalibrateReport RunCalibrate(const std::string& log_path, const std::string& out_dir, const PipelineConfig& config,
                             const std::function<void(const std::string&)>& progress = nullptr);

}  // namespace fusecal
