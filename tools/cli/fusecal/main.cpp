// `fusecal`: one executable, one subcommand per job.
#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "runtime/version.hpp"

int main(int argc, char** argv) {
  CLI::App app{"fusecal: targetless LiDAR-camera extrinsic calibration from sensor motion"};
  app.set_version_flag("--version", std::string(fusecal::kFusecalVersion));
  app.require_subcommand(1);
  int exit_code = 0;
  fusecal::AddDoctorCommand(app, &exit_code);
  fusecal::AddLogCommands(app, &exit_code);
  fusecal::AddEvaluateCommand(app, &exit_code);
  fusecal::AddExportCommand(app, &exit_code);
  fusecal::AddImportCommands(app, &exit_code);
  fusecal::AddSimulateCommand(app, &exit_code);
  fusecal::AddHandEyeCommand(app, &exit_code);
  fusecal::AddCalibrateCommand(app, &exit_code);
  fusecal::AddRunCommand(app, &exit_code);
  fusecal::AddStageCommands(app, &exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  return exit_code;
}
