// The common `main` of a stage process: flags (--config, --bus, --camera, --paced, --help, --version),
// clean exit on SIGINT/SIGTERM, a STATUS heartbeat at 1 Hz (sooner when the node asks), and a loop that
// dispatches messages. A handler that throws is reported (stderr and STATUS.last_error) and the process
// keeps running: nothing computed is lost.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>

#include "runtime/bus.hpp"
#include "runtime/channels.hpp"
#include "runtime/config_reader.hpp"
#include "runtime/rig.hpp"

namespace fusecal {

// What a stage reports in its heartbeat.
struct StageStatus {
  std::string state = "running";
  std::map<std::string, double> counters;
};

class StageNode {
 public:
  virtual ~StageNode() = default;
  // Subscribe to the channels the stage needs.
  virtual void Start(Bus& bus) = 0;
  // Called about every TickPeriodMs() and after each batch of messages (timeouts, retries).
  virtual void Tick(Bus& bus, int64_t now_utime) {}
  // A node that polls an outside source in Tick (the ROS 2 input) asks for a shorter period.
  virtual int TickPeriodMs() const { return 100; }
  // Work is queued that the next Tick takes (Tick returns now and then so that the bus is served): the
  // loop calls Tick again without waiting for messages.
  virtual bool HasQueuedWork() const { return false; }
  // The input is a replay that waits for the pipeline (`fusecal run` without --live passes --paced): a
  // node that would skip raw frames to keep up queues them all instead, so that the run computes what
  // `fusecal calibrate` does.
  virtual void UsePacedInput() {}
  // True when the node's STATUS should go out now rather than at the next second (a paced detector
  // tells the player what it has done).
  virtual bool WantsStatusNow() { return false; }
  // The input has ended (a replayed log is exhausted): emit whatever is pending.
  virtual void Flush(Bus& bus) {}
  virtual StageStatus Status() const = 0;
};

struct StageDefinition {
  std::string name;            // e.g. "handeye"; STATUS is published with this name
  std::string description;     // one line for --help
  std::string default_config;  // path used when --config is not given; may be empty
  bool per_camera = false;     // one process per camera of the rig (`--camera NAME`)
  // Builds the node from a config file path (empty: defaults) and, for a per-camera stage, its camera
  // (`--camera`). Throws ConfigError on bad config.
  std::function<std::unique_ptr<StageNode>(const std::string& config_path, const std::string& camera)> make_node;
};

// The section `name` of the pipeline config file (an empty section when absent). Only that section is
// checked here; `fusecal run` and `fusecal calibrate` check the whole file.
ConfigReader StageSection(const std::string& config_path, const std::string& name);

// The rig of the pipeline config file (its `cameras`) with `camera` as this process's camera. Throws
// ConfigError when a per-camera stage is not told which of several cameras it serves, or `camera` is not
// one of the rig's (or is given to a stage that serves the whole rig).
Rig StageRig(const std::string& config_path, const std::string& camera, bool per_camera);

// The name a stage's STATUS carries: `stage`, or `stage/camera` for a per-camera stage of a named camera.
std::string StageStatusName(const std::string& stage, const std::string& camera);

// Runs a stage until SIGINT/SIGTERM. Returns the process exit status (0 on a clean stop, 2 on bad
// flags or config, 1 when the bus cannot start).
int StageMain(int argc, char** argv, const StageDefinition& stage);

// The `main` of a stage whose node is built from the settings in its section of the config, e.g.
//   int main(int argc, char** argv) {
//     return RunStage<LidarIcpNode>(argc, argv, "lidar_icp", "fusecal-lidar-icp: ...", ReadLidarIcpNodeSettings);
//   }
template <typename Node, typename Settings>
int RunStage(int argc, char** argv, const std::string& name, const std::string& description,
             Settings (*read_settings)(ConfigReader section)) {
  StageDefinition stage;
  stage.name = name;
  stage.description = description;
  stage.per_camera = IsPerCameraStage<Settings>::value;
  stage.make_node = [read_settings, name](const std::string& config_path,
                                          const std::string& camera) -> std::unique_ptr<StageNode> {
    Settings settings;
    if (!config_path.empty()) settings = read_settings(StageSection(config_path, name));
    ApplyRig(StageRig(config_path, camera, IsPerCameraStage<Settings>::value), &settings);
    return std::make_unique<Node>(settings);
  };
  return StageMain(argc, argv, stage);
}

// Builds and publishes one STATUS message.
void PublishStatus(Bus& bus, const std::string& name, const StageStatus& status, const std::string& last_error);

}  // namespace fusecal
