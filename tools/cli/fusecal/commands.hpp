// Each subcommand of `fusecal` registers itself on the CLI11 app. A command's callback stores its
// exit status in *exit_code.
#pragma once

namespace CLI {
class App;
}

namespace fusecal {

void AddDoctorCommand(CLI::App& app, int* exit_code);
void AddLogCommands(CLI::App& app, int* exit_code);
void AddEvaluateCommand(CLI::App& app, int* exit_code);
void AddExportCommand(CLI::App& app, int* exit_code);
void AddImportCommands(CLI::App& app, int* exit_code);
void AddSimulateCommand(CLI::App& app, int* exit_code);
void AddHandEyeCommand(CLI::App& app, int* exit_code);
void AddCalibrateCommand(CLI::App& app, int* exit_code);
void AddRunCommand(CLI::App& app, int* exit_code);
void AddStageCommands(CLI::App& app, int* exit_code);

}  // namespace fusecal
