// `fusecal evaluate --result RESULT.yaml --truth LOG_OR_YAML [--at-utime UTIME]`: one JSON line with the
// error against the extrinsic in force at the log's end (or at UTIME), and the utime it holds from. A rig's
// result (stages/formats/rig_file.hpp) gives each camera's error under "cameras", and each derived
// camera-to-camera transform's error and std under "camera_to_camera".
#include <CLI/CLI.hpp>
#include <cstdint>
#include <iostream>
#include <optional>

#include "commands.hpp"
#include "stages/formats/ground_truth.hpp"
#include "stages/formats/message_json.hpp"
#include "stages/formats/result_file.hpp"
#include "stages/formats/rig_file.hpp"
#include "stages/foundation/extrinsic_error.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal {

namespace {

// A result or truth that is NaN, all zeros or not a rotation gives no error worth printing.
Isometry3 CheckedTransform(const Isometry3& T, const std::string& what, const std::string& path) {
  if (!IsValidTransform(T))
    throw std::runtime_error(what + " " + path +
                             ": T_camera_lidar is not a rigid transform (non-finite, or its "
                             "rotation is not orthonormal with determinant 1)");
  return T;
}

// A rig's result against the truth of each camera.
OrderedJson EvaluateRig(const std::string& result_path, const std::string& truth_path,
                        std::optional<int64_t> at_utime) {
  const RigResult rig = ReadRigFile(result_path);
  OrderedJson cameras = OrderedJson::object(), pairs = OrderedJson::object();
  std::map<std::string, Isometry3> truths;
  double max_rotation = 0, max_translation = 0;
  for (const auto& c : rig.cameras) {
    const ReferenceExtrinsic reference = ReadReference(truth_path, at_utime, c.camera);
    truths[c.camera] = CheckedTransform(reference.T_camera_lidar, "--truth", truth_path);
    const ExtrinsicError e = CompareExtrinsics(c.T_camera_lidar, truths[c.camera]);
    OrderedJson entry{{"rot_err_deg", e.rotation_deg}, {"trans_err_m", e.translation_m}, {"status", c.status}};
    if (reference.from_utime) entry["truth_from_utime"] = *reference.from_utime;
    cameras[c.camera] = entry;
    max_rotation = std::max(max_rotation, e.rotation_deg);
    max_translation = std::max(max_translation, e.translation_m);
  }
  for (const auto& c : rig.camera_to_camera) {
    const Isometry3 truth = truths.at(c.to) * truths.at(c.from).inverse();
    const ExtrinsicError e = CompareExtrinsics(c.T, truth);
    OrderedJson entry{{"rot_err_deg", e.rotation_deg}, {"trans_err_m", e.translation_m}};
    if (c.covariance) {
      // The error in the covariance's own terms (stages/formats/rig_file.hpp): how many std it lies off.
      Eigen::Matrix<double, 6, 1> d;
      d.head<3>() = LogSO3(c.T.linear().transpose() * truth.linear());
      d.tail<3>() = truth.translation() - c.T.translation();
      const Eigen::Matrix<double, 6, 1> sigma = c.covariance->diagonal().cwiseSqrt();
      entry["rot_std_deg"] = RotationStdDevDeg(*c.covariance).maxCoeff();
      entry["trans_std_m"] = TranslationStdDevM(*c.covariance).maxCoeff();
      entry["max_err_in_std"] = d.cwiseQuotient(sigma).cwiseAbs().maxCoeff();
    }
    pairs[c.to + "_" + c.from] = entry;
  }
  return OrderedJson{{"max_rot_err_deg", max_rotation},
                     {"max_trans_err_m", max_translation},
                     {"cameras", cameras},
                     {"camera_to_camera", pairs}};
}

}  // namespace

void AddEvaluateCommand(CLI::App& app, int* exit_code) {
  auto* evaluate = app.add_subcommand("evaluate", "error of a result file against the ground truth");
  static std::string result_path, truth_path;
  static int64_t at_utime = 0;
  evaluate->add_option("--result", result_path, "result file (YAML with T_camera_lidar)")->required();
  evaluate
      ->add_option("--truth", truth_path,
                   "log with GROUND_TRUTH (compared with the extrinsic in force at the log's end; the JSON "
                   "line gives truth_from_utime, the utime it holds from), or a reference result YAML "
                   "(no truth_from_utime)")
      ->required();
  auto* at_option = evaluate->add_option("--at-utime", at_utime,
                                         "compare with the log's extrinsic in force at this utime (microseconds) "
                                         "instead of at its end, for a camera moved on its mount mid-session");
  evaluate->callback([exit_code, at_option] {
    try {
      if (IsRigFile(result_path)) {
        std::cout << EvaluateRig(result_path, truth_path,
                                 at_option->count() ? std::optional<int64_t>(at_utime) : std::nullopt)
                         .dump()
                  << "\n";
        *exit_code = 0;
        return;
      }
      const CalibrationResult result = ReadResultFile(result_path);
      const Isometry3 estimate = CheckedTransform(result.T_camera_lidar, "--result", result_path);
      const ReferenceExtrinsic reference =
          ReadReference(truth_path, at_option->count() ? std::optional<int64_t>(at_utime) : std::nullopt);
      const Isometry3 truth = CheckedTransform(reference.T_camera_lidar, "--truth", truth_path);
      const ExtrinsicError e = CompareExtrinsics(estimate, truth);
      OrderedJson line{
          {"rot_err_deg", e.rotation_deg},
          {"trans_err_m", e.translation_m},
          {"trans_err_xyz_m", {e.translation_xyz_m.x(), e.translation_xyz_m.y(), e.translation_xyz_m.z()}}};
      if (reference.from_utime) line["truth_from_utime"] = *reference.from_utime;
      if (result.unobservable_direction) {
        // Only the part the motions observed (docs/design.md section 1, step 6) can be compared.
        const ObservableError o = CompareObservablePart(estimate, truth, *result.unobservable_direction);
        line["unobservable_direction"] = {result.unobservable_direction->x(), result.unobservable_direction->y(),
                                          result.unobservable_direction->z()};
        line["observable_direction_err_deg"] = o.direction_deg;
        line["trans_err_perpendicular_m"] = o.translation_perpendicular_m.norm();
      }
      std::cout << line.dump() << "\n";
      *exit_code = 0;
    } catch (const std::exception& e) {
      std::cerr << "fusecal evaluate: " << e.what() << "\n";
      *exit_code = 1;
    }
  });
}

}  // namespace fusecal
