#include "runtime/pipeline/stage_nodes.hpp"

#include "runtime/pipeline/stage_registry.hpp"

namespace fusecal {

std::vector<NamedNode> MakeStageNodes(const PipelineConfig& config, bool with_stationarity) {
  std::vector<NamedNode> nodes;
  for (const StageInfo& stage : StageRegistry()) {
    if (!stage.in_process || (stage.name == "stationarity" && !with_stationarity)) continue;
    if (!stage.per_camera) {
      nodes.push_back({stage.name, MakeStageNode(stage.name, config)});
      continue;
    }
    for (const std::string& camera : config.cameras)
      nodes.push_back({StageStatusName(stage.name, camera), MakeStageNode(stage.name, config, camera)});
  }
  return nodes;
}

}  // namespace fusecal
