// `fusecal calibrate --log LOG --out DIR [--config configs/pipeline.yaml]`.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "runtime/pipeline/calibrate.hpp"

namespace fusecal {

void AddCalibrateCommand(CLI::App& app, int* exit_code) {
  auto* cmd = app.add_subcommand("calibrate", "all stages in one process over a log (deterministic)");
  static std::string log, out, config = DefaultPipelineConfigPath();
  cmd->add_option("--log", log, "LCM log (raw streams or stations)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", out, "output folder")->required();
  cmd->add_option("--config", config, "pipeline config");
  cmd->callback([exit_code] {
    try {
      const PipelineConfig pipeline = LoadPipelineConfig(config);
      const bool tty = isatty(STDERR_FILENO);
      const CalibrateReport report = RunCalibrate(log, out, pipeline, [tty](const std::string& line) {
        if (tty)
          std::cerr << "\r\033[K" << line << std::flush;
        else
          std::cerr << line << "\n";
      });
      if (tty) std::cerr << "\n";
      std::cout << (report.rig ? RigSummaryText(*report.rig, out) : SummaryText(report.outputs, out));
      std::cout << std::fixed << std::setprecision(2) << "time: " << report.total_seconds << " s total (";
      if (report.span_s > 0)
        std::cout << report.total_seconds / report.span_s << " x the recording's " << report.span_s << " s; ";
      std::cout << "outputs " << report.outputs_seconds << " s);";
      std::cout << StageBusyText(report.stage_counters);
      std::cout << "\n" << StageTableText(report.stage_counters, report.span_s);
      *exit_code = (report.rig ? AllConverged(*report.rig) : FinalConverged(report.outputs)) ? 0 : 1;
    } catch (const std::exception& e) {
      std::cerr << "fusecal calibrate: " << e.what() << "\n";
      *exit_code = 1;
    }
  });
}

}  // namespace fusecal
