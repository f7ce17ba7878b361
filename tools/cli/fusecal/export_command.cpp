// `fusecal export RESULT.yaml --format kitti|ros-static-tf|json|opencv-yaml|urdf [--out FILE]
//  [--parent-frame NAME] [--child-frame NAME]`.
#include <CLI/CLI.hpp>
#include <iostream>

#include "commands.hpp"
#include "runtime/output_file.hpp"
#include "stages/formats/extrinsic_formats.hpp"

namespace fusecal {

void AddExportCommand(CLI::App& app, int* exit_code) {
  auto* cmd = app.add_subcommand("export", "write a result in the format of another stack");
  static std::string result_path, format, out_path;
  static ExportFrames frames;
  cmd->add_option("RESULT", result_path,
                  "result file (YAML with T_camera_lidar, or a rig's with T_<camera>_lidar: one transform per camera, "
                  "the LiDAR the parent frame)")
      ->required();
  cmd->add_option("--format", format, "kitti, ros-static-tf, json, opencv-yaml or urdf")
      ->required()
      ->check(CLI::IsMember(ExportFormats()));
  cmd->add_option("--out", out_path, "output file (default: standard output)");
  cmd->add_option("--parent-frame", frames.parent, "the camera's (optical) frame in ros-static-tf and urdf")
      ->capture_default_str();
  cmd->add_option("--child-frame", frames.child, "the LiDAR's frame in ros-static-tf and urdf")->capture_default_str();
  cmd->callback([exit_code] {
    try {
      // A rig's result (several cameras): one transform per camera.
      const std::string text = IsRigFile(result_path) ? ExportRig(ReadRigFile(result_path), format, frames)
                                                      : ExportExtrinsic(ReadResultFile(result_path), format, frames);
      if (out_path.empty()) {
        std::cout << text;
      } else {
        WriteFileChecked(out_path, text);
      }
      *exit_code = 0;
    } catch (const std::exception& e) {
      std::cerr << "fusecal export: " << e.what() << "\n";
      *exit_code = 1;
    }
  });
}

}  // namespace fusecal
