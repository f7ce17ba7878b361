// `fusecal handeye --motions FILE.csv [--camera-scale per-motion|global|metric] --out RESULT.yaml`: offline
// hand-eye solve. The camera translations are directions (one unknown scale per motion, e.g. from essential
// matrices), a trajectory with one unknown scale (structure from motion, monocular SLAM), or metric. Rows
// where the extrinsic changed (a sensor moved on its mount) split the rows into parts, each solved alone;
// the last part is the result (handeye/segmented_solve.hpp).
#include <CLI/CLI.hpp>
#include <cmath>
#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "stages/handeye/global_scale.hpp"
#include "stages/handeye/node/motion_csv.hpp"
#include "stages/handeye/node/result_conversion.hpp"
#include "stages/handeye/segmented_solve.hpp"

namespace fusecal {

namespace {

void PrintSummary(const CalibrationResult& r) {
  const Eigen::Vector3d t = r.T_camera_lidar.translation();
  const Eigen::Vector3d rpy = RpyFromRotation(r.T_camera_lidar.linear()) * 180.0 / M_PI;
  std::cout << std::fixed << std::setprecision(4);
  std::cout << "T_camera_lidar: translation [" << t.x() << ", " << t.y() << ", " << t.z() << "] m, rpy [" << rpy.x()
            << ", " << rpy.y() << ", " << rpy.z() << "] deg\n";
  if (r.covariance) {
    const Eigen::Vector3d sr = RotationStdDevDeg(*r.covariance), st = TranslationStdDevM(*r.covariance);
    std::cout << "std dev: rotation [" << sr.x() << ", " << sr.y() << ", " << sr.z() << "] deg, translation [" << st.x()
              << ", " << st.y() << ", " << st.z() << "] m\n";
  }
  std::cout << "status: " << r.status << ", observability: " << r.observability
            << ", motions used: " << r.motions_used.size() << ", rejected: " << r.motions_rejected.size() << "\n";
  for (const auto& rejected : r.motions_rejected) std::cout << "  rejected " << rejected << "\n";
}

std::string RowName(int i, int j) {
  return "row " + std::to_string(j) + " (" + std::to_string(i) + "-" + std::to_string(j) + ")";
}

// Each change with its size: from the part before it to the part after it.
std::vector<ExtrinsicChangeRecord> ChangeRecords(const SegmentedSolve& solved) {
  std::vector<ExtrinsicChangeRecord> records;
  for (size_t k = 0; k < solved.changes.size(); ++k) {
    const ExtrinsicChange& c = solved.changes[k];
    const HandEyeResult& after = solved.segments[k + 1].result;
    ExtrinsicChangeRecord r = MakeChangeRecord(c.after_station, c.decided_at_station, c.T_before, c.covariance_before,
                                               after.T_camera_lidar, after.covariance);
    if (!after.usable())  // no size without a solve of the part after it
      r.rotation_deg = r.rotation_std_deg = r.translation_m = r.translation_std_m = std::nan("");
    records.push_back(r);
  }
  return records;
}

// Prints every part and change; writes the last part's result (and with `all`, every part's).
void Report(const SegmentedSolve& solved, const std::string& out, bool all) {
  const std::vector<ExtrinsicChangeRecord> records = ChangeRecords(solved);
  for (size_t k = 0; k < solved.segments.size(); ++k) {
    const PairSegment& part = solved.segments[k];
    CalibrationResult file = ToCalibrationResult(part.result, RowName);
    if (solved.segments.size() > 1)
      std::cout << "part " << k + 1 << " of " << solved.segments.size() << ": rows " << part.first + 1 << "-"
                << part.last + 1 << "\n";
    PrintSummary(file);
    if (!part.result.message.empty()) std::cout << part.result.message << "\n";
    if (k < records.size()) {
      const ExtrinsicChangeRecord& c = records[k];
      std::cout << "CHANGED in row " << solved.change_pairs[k] + 1 << " (after station " << c.after_station
                << ", decided at row " << c.decided_at_station << "): " << c.rotation_deg << " +- "
                << c.rotation_std_deg << " deg, " << c.translation_m << " +- " << c.translation_std_m << " m\n";
    }
    const bool last = k + 1 == solved.segments.size();
    if (!last && !all) continue;
    file.changes = std::vector<ExtrinsicChangeRecord>(records.begin(), records.begin() + std::min(k, records.size()));
    const std::string path =
        last ? out
             : out.substr(0, out.rfind(".yaml") == std::string::npos ? out.size() : out.rfind(".yaml")) + "-part" +
                   std::to_string(k + 1) + ".yaml";
    WriteResultFile(path, file);
    std::cout << "wrote " << path << "\n";
  }
}

}  // namespace

void AddHandEyeCommand(CLI::App& app, int* exit_code) {
  auto* cmd = app.add_subcommand("handeye", "solve T_camera_lidar from motion pairs (CSV)");
  static std::string motions, out, camera_scale = "per-motion";
  static bool scaled = false, all_parts = false, no_changes = false;
  cmd->add_option("--motions", motions, "CSV: a_qw..a_tz (camera T_ci_cj), b_qw..b_tz (LiDAR T_li_lj)")->required();
  cmd->add_option("--camera-scale", camera_scale,
                  "camera translations: per-motion (directions, one unknown scale each; default), global (one "
                  "unknown scale for the whole trajectory: structure from motion, SLAM) or metric")
      ->check(CLI::IsMember({"per-motion", "global", "metric"}));
  cmd->add_flag("--camera-scaled", scaled, "the same as --camera-scale metric");
  cmd->add_option("--out", out, "result file to write: the part after the last change of the extrinsic")->required();
  cmd->add_flag("--all-parts", all_parts, "also write each earlier part, as OUT-part<k>.yaml");
  cmd->add_flag("--no-changes", no_changes, "solve all rows as one, without looking for changes");
  cmd->callback([exit_code] {
    try {
      if (scaled) camera_scale = "metric";
      const bool metric = camera_scale == "metric";
      const MotionCsv csv = ReadMotionCsv(motions, metric);
      for (const auto& p : csv.problems) std::cerr << "fusecal handeye: " << p << "\n";
      const PairSolver solve = [&](const std::vector<MotionPair>& pairs) {
        return metric ? SolveScaled(pairs) : camera_scale == "global" ? SolveGlobalScale(pairs) : SolveScaleless(pairs);
      };
      ChangeDetectionSettings detection;
      detection.enabled = !no_changes;
      const SegmentedSolve solved = SolveWithChanges(csv.pairs, solve, detection, HandEyeSettings{});
      Report(solved, out, all_parts);
      const HandEyeResult& result = solved.segments.back().result;
      *exit_code = result.converged ? 0 : 1;
    } catch (const std::exception& e) {
      std::cerr << "fusecal handeye: " << e.what() << "\n";
      *exit_code = 1;
    }
  });
}

}  // namespace fusecal
