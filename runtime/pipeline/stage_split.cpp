#include "runtime/pipeline/stage_split.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "runtime/pipeline/stage_registry.hpp"
#include "runtime/rig.hpp"

namespace fusecal {

namespace {
bool Contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}
}  // namespace

const std::vector<std::string>& KnownStageNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all;
    for (const StageInfo& stage : StageRegistry()) all.push_back(stage.name);
    return all;
  }();
  return names;
}

std::vector<std::string> PipelineStageNames(bool with_stationarity, bool with_ros2_tf, bool with_ros2_input,
                                            const std::vector<std::string>& cameras) {
  std::vector<std::string> names;
  for (const auto& name : KnownStageNames()) {
    if ((name == "stationarity" && !with_stationarity) || (name == "ros2_tf" && !with_ros2_tf) ||
        (name == "ros2_input" && !with_ros2_input))
      continue;
    if (!FindStage(name)->per_camera || cameras.front().empty()) {
      names.push_back(name);
      continue;
    }
    for (const auto& camera : cameras) names.push_back(name + "/" + camera);
  }
  return names;
}

std::pair<std::string, std::string> StageAndCamera(const std::string& name) {
  const size_t slash = name.find('/');
  if (slash == std::string::npos) return {name, ""};
  return {name.substr(0, slash), name.substr(slash + 1)};
}

std::vector<std::string> ParseStageList(const std::string& list) {
  std::vector<std::string> names;
  std::istringstream in(list);
  for (std::string name; std::getline(in, name, ',');) {
    if (name.empty()) continue;
    const auto [stage, camera] = StageAndCamera(name);
    if (!Contains(KnownStageNames(), stage))
      throw std::invalid_argument("unknown stage '" + name + "' (the stages: " + JoinNames(KnownStageNames()) + ")");
    if (name.find('/') != std::string::npos && !FindStage(stage)->per_camera)
      throw std::invalid_argument("stage '" + stage + "' serves the whole rig: list it without a camera");
    if (name.find('/') != std::string::npos && !CameraNameProblem(camera).empty())
      throw std::invalid_argument("stage '" + name + "': the camera name " + CameraNameProblem(camera));
    if (Contains(names, name)) throw std::invalid_argument("stage '" + name + "' is listed twice");
    names.push_back(name);
  }
  if (names.empty()) throw std::invalid_argument("no stage listed (the stages: " + JoinNames(KnownStageNames()) + ")");
  return names;
}

StageSplit SplitStages(const std::vector<std::string>& pipeline, const std::vector<std::string>& selected) {
  StageSplit split;
  for (const auto& name : pipeline) {
    const bool chosen = selected.empty() || Contains(selected, name) || Contains(selected, StageAndCamera(name).first);
    (chosen ? split.here : split.elsewhere).push_back(name);
  }
  for (const auto& name : selected) {
    bool in_pipeline = Contains(pipeline, name);
    for (const auto& instance : pipeline) in_pipeline = in_pipeline || StageAndCamera(instance).first == name;
    if (!in_pipeline) split.not_needed.push_back(name);
  }
  return split;
}

std::string JoinNames(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& name : names) out += (out.empty() ? "" : ",") + name;
  return out;
}

}  // namespace fusecal
