// `fusecal handeye --motions FILE.csv [--camera-scale per-motion|global|metric] --out RESULT.yaml`: offline
// hand-eye solve. The camera translations are directions (one unknown scale per motion, e.g. from essential
// matrices), a trajectory with one unknown scale (structure from motion, monocular SLAM), or metric.
#include <CLI/CLI.hpp>
#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "handeye/global_scale.hpp"
#include "handeye/node/motion_csv.hpp"
#include "handeye/node/result_conversion.hpp"

namespace fusecal {

namespace {

void PrintSummary(const CalibrationResult& r) {
  const Eigen::Vector3d t = r.T_camera_lidar.translation();
  const Eigen::Vector3d rpy = RpyFromRotation(r.T_camera_lidar.linear()) * 180.0 / M_PI;
  std::cout << std::fixed << std::setprecision(4);
  std::cout << "T_camera_lidar: translation [" << t.x() << ", " << t.y() << ", " << t.z() << "] m, rpy ["
            << rpy.x() << ", " << rpy.y() << ", " << rpy.z() << "] deg\n";
  if (r.covariance) {
    const Eigen::Vector3d sr = RotationStdDevDeg(*r.covariance), st = TranslationStdDevM(*r.covariance);
    std::cout << "std dev: rotation [" << sr.x() << ", " << sr.y() << ", " << sr.z() << "] deg, translation ["
              << st.x() << ", " << st.y() << ", " << st.z() << "] m\n";
  }
  std::cout << "status: " << r.status << ", observability: " << r.observability << ", motions used: "
            << r.motions_used.size() << ", rejected: " << r.motions_rejected.size() << "\n";
  for (const auto& rejected : r.motions_rejected) std::cout << "  rejected " << rejected << "\n";
}

}  // namespace

void AddHandEyeCommand(CLI::App& app, int* exit_code) {
  auto* cmd = app.add_subcommand("handeye", "solve T_camera_lidar from motion pairs (CSV)");
  static std::string motions, out, camera_scale = "per-motion";
  static bool scaled = false;
  cmd->add_option("--motions", motions, "CSV: a_qw..a_tz (camera T_ci_cj), b_qw..b_tz (LiDAR T_li_lj)")->required();
  cmd->add_option("--camera-scale", camera_scale,
                  "camera translations: per-motion (directions, one unknown scale each; default), global (one "
                  "unknown scale for the whole trajectory: structure from motion, SLAM) or metric")
      ->check(CLI::IsMember({"per-motion", "global", "metric"}));
  cmd->add_flag("--camera-scaled", scaled, "the same as --camera-scale metric");
  cmd->add_option("--out", out, "result file to write")->required();
  cmd->callback([exit_code] {
    try {
      if (scaled) camera_scale = "metric";
      const bool metric = camera_scale == "metric";
      const MotionCsv csv = ReadMotionCsv(motions, metric);
      for (const auto& p : csv.problems) std::cerr << "fusecal handeye: " << p << "\n";
      const HandEyeResult result = metric                      ? SolveScaled(csv.pairs)
                                   : camera_scale == "global" ? SolveGlobalScale(csv.pairs)
                                                              : SolveScaleless(csv.pairs);
      const CalibrationResult file =
          ToCalibrationResult(result, [](int i, int j) { return "row " + std::to_string(j) + " (" + std::to_string(i) + "-" + std::to_string(j) + ")"; });
      WriteResultFile(out, file);
      PrintSummary(file);
      if (!result.message.empty()) std::cout << result.message << "\n";
      std::cout << "wrote " << out << "\n";
      *exit_code = result.converged ? 0 : 1;
    } catch (const std::exception& e) {
      std::cerr << "fusecal handeye: " << e.what() << "\n";
      *exit_code = 1;
    }
  });
}

}  // namespace fusecal
