// `fusecal run --config configs/pipeline.yaml [--log LOG [--speed X] [--live]] [--stages A,B] --out DIR`.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <csignal>
#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "runtime/pipeline/run.hpp"

namespace fusecal {

namespace {
std::atomic<bool> g_stop{false};
void OnSignal(int) { g_stop = true; }

// What is wrong with the combination of flags (empty: nothing).
std::string ProblemWithOptions(const RunOptions& options) {
  if (!std::isfinite(options.speed))
    return "--speed must be a finite number >= 0 (0: as fast as the stages go), not " + std::to_string(options.speed);
  if (options.ros2 && !options.log_path.empty())
    return "--ros2 takes the sensors from a running ROS 2 robot; it cannot be given --log (import a ROS 2 bag "
           "with `fusecal import rosbag` and give that log instead)";
  if (options.live && (options.log_path.empty() || options.speed <= 0))
    return "--live plays a log at recorded time: give --log and a --speed above 0";
  return {};
}
}  // namespace

void AddRunCommand(CLI::App& app, int* exit_code) {
  auto* cmd = app.add_subcommand("run", "the stages as separate processes on the bus, supervised");
  static std::string config = DefaultPipelineConfigPath();
  static RunOptions options;
  static std::string stages;
  cmd->add_option("--config", config, "pipeline config (the stages are given the same file)");
  cmd->add_option("--log", options.log_path, "LCM log to play into the bus (default: live sensors)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--speed", options.speed, "replay speed (1 = recorded timing, 0 = as fast as the stages go)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--live", options.live,
                "play the log at recorded time (x speed) without waiting for the stages, as sensors do; "
                "writes latency.csv");
  cmd->add_flag("--ros2", options.ros2,
                "calibrate a running ROS 2 robot: its sensor topics (config section ros2_input) in, the "
                "extrinsic out on rt/tf_static and in extrinsic.yaml at each converged version, until Ctrl-C");
  cmd->add_option("--bus", options.bus_url, "bus URL (default: the config's)");
  auto* stages_option =
      cmd->add_option("--stages", stages,
                      "start only these stages, e.g. fusion_odometry,handeye; the others run on other hosts on the "
                      "same bus (without --log: ends when the host playing the log is done)");
  cmd->add_option("--out", options.out_dir, "output folder")->required();
  cmd->callback([exit_code, stages_option] {
    if (const std::string problem = ProblemWithOptions(options); !problem.empty()) {
      std::cerr << "fusecal run: " << problem << "\n";
      *exit_code = 2;
      return;
    }
    try {
      if (stages_option->count() > 0) options.stages = ParseStageList(stages);  // '' is "no stage listed"
    } catch (const std::invalid_argument& e) {
      std::cerr << "fusecal run: --stages: " << e.what() << "\n";
      *exit_code = 2;
      return;
    }
    std::signal(SIGINT, OnSignal);
    std::signal(SIGTERM, OnSignal);
    const bool tty = isatty(STDERR_FILENO);
    try {
      const PipelineConfig pipeline = LoadPipelineConfig(config);
      const RunReport report = RunPipeline(
          pipeline, options, g_stop,
          [tty](const std::string& line) {
            if (tty)
              std::cerr << "\r\033[K" << line << std::flush;
            else
              std::cerr << line << "\n";
          },
          [tty](const std::string& line) { std::cerr << (tty ? "\r\033[K" : "") << line << "\n"; });
      if (tty) std::cerr << "\n";
      if (g_stop) std::cerr << "stopped by signal; writing what was computed\n";
      std::cout << (report.rig ? RigSummaryText(*report.rig, options.out_dir)
                               : SummaryText(report.outputs, options.out_dir));
      std::cout << std::fixed << std::setprecision(2) << "time: " << report.total_seconds << " s total (";
      if (report.span_s > 0)
        std::cout << report.total_seconds / report.span_s << " x the recording's " << report.span_s << " s: ";
      std::cout << "startup " << report.startup_seconds << " s, ";
      if (options.log_path.empty())
        std::cout << "listening " << report.listen_seconds << " s, ";
      else
        std::cout << "replay " << report.replay_seconds << " s, after the log " << report.after_log_seconds << " s, ";
      std::cout << "stop and outputs " << report.outputs_seconds << " s);";
      std::cout << StageBusyText(report.stage_counters);
      std::cout << "; stage restarts: " << report.restarts;
      if (report.roudi_restarts > 0) std::cout << "; RouDi restarts: " << report.roudi_restarts;
      if (report.bus_counts_losses) std::cout << "; messages lost by the bus: " << report.bus_dropped;
      std::cout << "\n" << StageTableText(report.stage_counters, report.span_s) << LatencyText(report.latencies);
      *exit_code = (report.rig ? AllConverged(*report.rig) : FinalConverged(report.outputs)) ? 0 : 1;
      if (!report.failure.empty()) {
        std::cerr << "fusecal run: " << report.failure << "\n";
        *exit_code = 1;
      }
    } catch (const std::exception& e) {
      std::cerr << "\nfusecal run: " << e.what() << "\n";
      *exit_code = 1;
    }
  });
}

}  // namespace fusecal
