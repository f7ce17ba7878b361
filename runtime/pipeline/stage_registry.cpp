#include "runtime/pipeline/stage_registry.hpp"

#include <algorithm>
#include <sstream>

#include "runtime/pipeline/pipeline_config.hpp"

namespace fusecal {
namespace {

// The node slot of a stage that only runs as a process (stages/stages.def).
struct NoInProcessNode {};

std::vector<std::string> Words(const char* text) {
  std::vector<std::string> words;
  std::istringstream in(text);
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

template <typename Node>
constexpr bool kInProcess = !std::is_same_v<Node, NoInProcessNode>;

template <typename Node, typename Settings>
std::unique_ptr<StageNode> MakeNode(Settings settings, const std::string& camera) {
  if constexpr (IsPerCameraStage<Settings>::value) settings.camera = camera;
  if constexpr (kInProcess<Node>)
    return std::make_unique<Node>(settings);
  else
    return nullptr;
}

}  // namespace

std::string StageInfo::Executable() const {
  std::string executable = "fusecal-" + name;
  std::replace(executable.begin() + 8, executable.end(), '_', '-');
  return executable;
}

const std::vector<StageInfo>& StageRegistry() {
  static const std::vector<StageInfo> registry = {
#define FUSECAL_STAGE(name, header, Settings, read, Node, in, out) \
  {#name, Words(in), Words(out), kInProcess<Node>, IsPerCameraStage<Settings>::value},
#include "stages/stages.def"
#undef FUSECAL_STAGE
  };
  return registry;
}

const StageInfo* FindStage(const std::string& name) {
  for (const StageInfo& stage : StageRegistry())
    if (stage.name == name) return &stage;
  return nullptr;
}

std::unique_ptr<StageNode> MakeStageNode(const std::string& name, const PipelineConfig& config,
                                         const std::string& camera) {
#define FUSECAL_STAGE(stage, header, Settings, read, Node, in, out) \
  if (name == #stage) return MakeNode<Node>(config.stage, camera);
#include "stages/stages.def"
#undef FUSECAL_STAGE
  return nullptr;
}

}  // namespace fusecal
