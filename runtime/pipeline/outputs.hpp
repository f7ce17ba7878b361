// The files a calibration leaves in its output folder:
//   extrinsic.yaml      the common result file, with the scaleless estimate as `initial`
//   convergence.csv/png per version: change, and error against ground truth when the log has it
//   overlay-<id>.png    per station (at most 12, spread over the stations still held): checkerboard of
//                       camera and LiDAR intensity images (the paper's check) above the camera image
//                       with projected points coloured by depth
//   colored_cloud.ply   the scan of the first station held, coloured from its image
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "runtime/pipeline/session.hpp"
#include "stages/formats/result_file.hpp"
#include "stages/formats/rig_file.hpp"
#include "stages/foundation/extrinsic_error.hpp"

namespace fusecal {

struct CalibrationOutputs {
  bool has_result = false;
  CalibrationResult final_result, initial_result;
  std::optional<ExtrinsicError> final_error, initial_error;  // against ground truth, when known
  std::optional<ObservableError> observable_error;           // when the result names an unobservable direction
  std::vector<std::string> files;
  std::vector<std::string> warnings;  // e.g. gnuplot missing, a file that could not be written
  bool result_file_written = false;   // extrinsic.yaml
};

CalibrationResult ResultFromMessage(const extrinsic_t& message);
// The changes of the extrinsic a version lists, each with its size (to the next change's estimate before,
// or to this version's estimate for the newest) and the std of that size.
std::vector<ExtrinsicChangeRecord> ChangeRecords(const extrinsic_t& message);

// Runs `write` (which returns the path it wrote) and lists the file, or its failure as a warning.
void AddOutputFile(CalibrationOutputs* outputs, const std::function<std::string()>& write);

CalibrationOutputs WriteCalibrationOutputs(const SessionRecord& session, const std::string& out_dir);

// One paragraph for the terminal: verdict, estimate, errors when known, where the files are.
std::string SummaryText(const CalibrationOutputs& outputs, const std::string& out_dir);

// Whether the final result has converged and its result file was written (`run` and `calibrate` exit
// with 0 then).
bool FinalConverged(const CalibrationOutputs& outputs);

// A rig of several cameras: each camera's outputs in <out_dir>/<camera>/, and the rig's extrinsic.yaml
// (stages/formats/rig_file.hpp) in out_dir.
struct CameraOutputs {
  std::string camera;
  CalibrationOutputs outputs;
};
struct RigOutputs {
  std::vector<CameraOutputs> cameras;
  std::optional<RigResult> rig;  // when every camera has a result
  std::optional<std::string> rig_file;
  std::vector<std::string> warnings;
};
RigOutputs WriteRigOutputs(const std::vector<const SessionRecord*>& sessions, const std::string& out_dir);
std::string RigSummaryText(const RigOutputs& outputs, const std::string& out_dir);
bool AllConverged(const RigOutputs& outputs);

// One progress line for the rig: ProgressText of the first camera, and each other camera's version and verdict.
std::string RigProgressText(const std::vector<const SessionRecord*>& sessions);

}  // namespace fusecal
