// The pipeline config (configs/pipeline.yaml): every section is checked, unknown keys are errors.
#pragma once

#include <string>

#include "runtime/pipeline/session_log.hpp"
#include "runtime/rig.hpp"
#include "stage_headers.hpp"  // generated from stages/stages.def: every stage's settings

namespace fusecal {

struct PipelineConfig {
  std::string path;  // the file it came from (stage processes are given the same file)
  std::string bus_url;
  // Shared memory (dds://?shm=1, iox://): RouDi's pools hold `shm_chunks` messages of up to max_message_bytes.
  size_t max_message_bytes = 12u << 20;
  int shm_chunks = 32;
  std::string stations_from = "auto";    // detector | log | auto
  std::vector<std::string> cameras{""};  // the rig's cameras (runtime/rig.hpp); {""}: one without a name
  // Each stage's settings, named as the stage (stages/stages.def): stationarity, lidar_icp, ..., ros2_input
  // (`fusecal run --ros2`) and ros2_tf.
#define FUSECAL_STAGE(name, header, Settings, read, Node, in, out) Settings name;
#include "stages/stages.def"
#undef FUSECAL_STAGE
  double idle_timeout_s = 60;
  RecordSettings record;  // run.record, run.record_max_raw_mb
};

// Throws ConfigError naming the file and key.
PipelineConfig LoadPipelineConfig(const std::string& path);

// The rig's cameras set to `cameras`, in every stage's settings too.
void SetRigCameras(PipelineConfig* config, const std::vector<std::string>& cameras);

// configs/pipeline.yaml of the source tree.
std::string DefaultPipelineConfigPath();

}  // namespace fusecal
