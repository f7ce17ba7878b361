// `fusecal run`: the stage executables as separate processes on the configured bus (LCM UDP multicast by
// default), a log played into the bus (or live sensors when no log is given), the whole session recorded,
// stages supervised (a crashed stage is restarted and given the stations again), and a clean shutdown on
// Ctrl-C. Stops when the extrinsic has settled and the log is exhausted.
//
// Replay is paced by the pipeline: after each station the player waits until the stages have answered
// it (motions, and the alternation settled), so a replay computes exactly what `calibrate` computes.
#pragma once

#include <atomic>
#include <functional>
#include <string>

#include "pipeline/outputs.hpp"
#include "pipeline/pipeline_config.hpp"

namespace fusecal {

struct RunOptions {
  std::string log_path;   // empty: live (listen until Ctrl-C)
  double speed = 1.0;     // replay speed; 0: as fast as the pipeline takes it
  std::string bus_url;    // empty: the config's
  std::string out_dir;
};

struct RunReport {
  CalibrationOutputs outputs;
  int restarts = 0;
  int roudi_restarts = 0;  // shared memory only: times RouDi was started again
  bool used_dds = false;
  double bus_dropped = 0;  // messages the buses of the stages and the coordinator know they lost (DDS)
  double total_seconds = 0;
  std::map<std::string, double> stage_seconds;
};

// `stop` is polled (Ctrl-C); `progress` gets status lines and `event` one-off messages (restarts).
RunReport RunPipeline(const PipelineConfig& config, const RunOptions& options, const std::atomic<bool>& stop,
                      const std::function<void(const std::string&)>& progress,
                      const std::function<void(const std::string&)>& event);

}  // namespace fusecal
