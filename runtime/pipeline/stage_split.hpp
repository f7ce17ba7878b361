// Which stages of the pipeline one `fusecal run` starts: all of them, or with `--stages` only those
// listed, the others running on other hosts on the same bus (docs/design.md section 5, "Stages on
// several hosts"). The host that plays the log waits for the heartbeats of the others before playing.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace fusecal {

// Every stage `fusecal run` can start, in start order (the stage registry, stages/stages.def): the names
// of the stage executables (fusecal-<name with dashes>) and of their STATUS.
const std::vector<std::string>& KnownStageNames();

// The stages of one pipeline in start order: ros2_input only for a live ROS 2 robot, stationarity only
// when it makes the stations, ros2_tf only when enabled. On a rig of named cameras a per-camera stage
// appears once per camera, as stage/camera (camera_frontend/front, camera_frontend/left, ...).
std::vector<std::string> PipelineStageNames(bool with_stationarity, bool with_ros2_tf, bool with_ros2_input = false,
                                            const std::vector<std::string>& cameras = {""});

// "stationarity,lidar_icp" as names; a per-camera stage may name one camera's (camera_frontend/left).
// Throws std::invalid_argument naming an unknown or repeated stage (and listing the known ones), or for
// an empty list.
std::vector<std::string> ParseStageList(const std::string& list);

// A pipeline stage's name split: {"camera_frontend", "left"} for camera_frontend/left, {name, ""} else.
std::pair<std::string, std::string> StageAndCamera(const std::string& name);

struct StageSplit {
  std::vector<std::string> here;        // started and supervised by this host, in start order
  std::vector<std::string> elsewhere;   // the pipeline's other stages, expected from other hosts
  std::vector<std::string> not_needed;  // listed but not in this pipeline (stationarity when the log has stations)
};

// `selected` empty: every stage of `pipeline` here. A per-camera stage selected by its name alone is
// selected for every camera.
StageSplit SplitStages(const std::vector<std::string>& pipeline, const std::vector<std::string>& selected);

// "a,b,c".
std::string JoinNames(const std::vector<std::string>& names);

}  // namespace fusecal
