// The stage nodes of the pipeline, built from one config, for running them in one process.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "runtime/pipeline/pipeline_config.hpp"
#include "runtime/stage_main.hpp"

namespace fusecal {

struct NamedNode {
  std::string name;
  std::unique_ptr<StageNode> node;
};

// The in-process stages of the registry (stages/stages.def) in start order, a per-camera stage once per
// camera of the rig (named stage/camera); stationarity only when it makes the stations.
std::vector<NamedNode> MakeStageNodes(const PipelineConfig& config, bool with_stationarity);

}  // namespace fusecal
