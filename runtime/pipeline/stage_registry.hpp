// The stage registry (stages/stages.def) as the coordinator reads it: every stage in start order with its
// executable and channels, and for the stages `fusecal calibrate` runs in one process, their node built
// from the pipeline config. The config's stage sections (PipelineConfig) come from the same entries.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "runtime/stage_main.hpp"

namespace fusecal {

struct PipelineConfig;

struct StageInfo {
  std::string name;                       // stages/<name>/, the config section, the name in STATUS
  std::vector<std::string> channels_in;   // what it subscribes to (besides nothing: STATUS is out only)
  std::vector<std::string> channels_out;  // what it publishes, besides STATUS
  bool in_process = false;                // `calibrate` runs its node in its own process
  bool per_camera = false;                // one per camera of the rig (camera front end, fusion odometry, hand-eye)

  // fusecal-<name with dashes>
  std::string Executable() const;
};

// Every stage, in start order.
const std::vector<StageInfo>& StageRegistry();

// The stage called `name`, or nullptr.
const StageInfo* FindStage(const std::string& name);

// The node of an in-process stage, built from its section of `config` (a per-camera stage's for `camera`);
// nullptr for a stage that only runs as a process (or an unknown name).
std::unique_ptr<StageNode> MakeStageNode(const std::string& name, const PipelineConfig& config,
                                         const std::string& camera = "");

}  // namespace fusecal
