// `fusecal run`: the stage executables as separate processes on the configured bus (LCM UDP multicast by
// default), a log played into the bus (or live sensors when no log is given), the whole session recorded,
// stages supervised (a crashed stage is restarted and given the stations again), and a clean shutdown on
// Ctrl-C. Stops when the extrinsic has settled and the log is exhausted.
//
// Replay is paced by the pipeline: after each station the player waits until the stages have answered
// it (motions, and the alternation settled), so a replay computes exactly what `calibrate` computes.
// Without a log, `ros2` listens to a running ROS 2 robot (RunOptions::ros2).
// Live replay (`live`) plays the log at recorded time (x speed) and never waits, as sensors do: stages
// that fall behind meet their overload policy (docs/design.md section 5), and the latency of the answer
// per station is measured (latency.csv).
//
// Stages on several hosts (`stages`): this run starts only the listed stages; the others run on other
// hosts on the same bus, under a `fusecal run --stages ...` of their own. The run with the log waits
// for every stage's heartbeat before it plays, paces the replay by the answers from all hosts, and
// says "done" (STATUS of kPlayerName) at the end; a run with `stages` and without a log ends when it
// hears that (and writes its outputs), as on Ctrl-C.
#pragma once

#include <atomic>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "runtime/pipeline/latency.hpp"
#include "runtime/pipeline/outputs.hpp"
#include "runtime/pipeline/pipeline_config.hpp"
#include "runtime/pipeline/stage_split.hpp"
#include "runtime/pipeline/stage_table.hpp"

namespace fusecal {

struct RunOptions {
  std::string log_path;  // empty: live (listen until Ctrl-C)
  double speed = 1.0;    // replay speed; 0: as fast as the pipeline takes it
  bool live = false;     // play at recorded time x speed without waiting for the stages
  std::string bus_url;   // empty: the config's
  std::string out_dir;
  std::vector<std::string> stages;  // the stages started here (`--stages`); empty: all
  // A live ROS 2 robot: fusecal-ros2-input feeds the pipeline from ROS 2 topics (config section
  // ros2_input), fusecal-ros2-tf publishes rt/tf_static, and the result file is written at each converged
  // version. Ends on Ctrl-C, or with `failure` set when the topics do not appear.
  bool ros2 = false;
};

struct RunReport {
  CalibrationOutputs outputs;     // the one camera's; on a rig of several, the first camera's
  std::optional<RigOutputs> rig;  // a rig of several cameras: each camera's and the rig file
  int restarts = 0;
  int roudi_restarts = 0;          // shared memory only: times RouDi was started again
  bool bus_counts_losses = false;  // dds:// and iox:// count what they lose (sequence gaps, full queues)
  double bus_dropped = 0;          // messages the buses of the stages and the coordinator know they lost
  double total_seconds = 0;
  // Where the time went: starting the stages, playing the log, the stages' work after its end,
  // stopping them and writing the outputs.
  double startup_seconds = 0, replay_seconds = 0, after_log_seconds = 0, outputs_seconds = 0;
  double listen_seconds = 0;              // without a log: until Ctrl-C or the player's "done"
  StageCounters stage_counters;           // each stage's last STATUS counters (busy_s, bus_dropped, ...; stages.csv)
  double span_s = 0;                      // recording span played
  std::vector<StationLatency> latencies;  // live replay only (latency.csv)
  std::string failure;                    // why the run ended by itself without a result (a ROS 2 topic never came)
};

// `stop` is polled (Ctrl-C); `progress` gets status lines and `event` one-off messages (restarts).
RunReport RunPipeline(const PipelineConfig& config, const RunOptions& options, const std::atomic<bool>& stop,
                      const std::function<void(const std::string&)>& progress,
                      const std::function<void(const std::string&)>& event);

}  // namespace fusecal
