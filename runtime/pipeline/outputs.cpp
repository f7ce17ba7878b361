#include "runtime/pipeline/outputs.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "runtime/io/visualization/overlay.hpp"
#include "runtime/output_file.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/extrinsic_status.hpp"
#include "stages/foundation/extrinsic_error.hpp"
#include "stages/foundation/extrinsic_verdict.hpp"

namespace fusecal {

namespace fs = std::filesystem;

std::vector<ExtrinsicChangeRecord> ChangeRecords(const extrinsic_t& e) {
  std::vector<ExtrinsicChangeRecord> records;
  for (int k = 0; k < e.num_changes; ++k) {
    // The size: to the estimate before the next change, or to this version's for the newest.
    const bool newest = k + 1 == e.num_changes;
    const double* after = newest ? e.T_camera_lidar : e.change_T_before[k + 1].data();
    const double* after_covariance = newest ? e.covariance : e.change_covariance_before[k + 1].data();
    records.push_back(MakeChangeRecord(e.change_after_station[k], e.change_decided_at_station[k],
                                       FromRowMajor(e.change_T_before[k].data()),
                                       Matrix6FromArray(e.change_covariance_before[k].data()), FromRowMajor(after),
                                       Matrix6FromArray(after_covariance)));
    if (newest && e.status == extrinsic_t::STATUS_FAILED) {
      // No estimate after the change yet: its size is not known.
      ExtrinsicChangeRecord& r = records.back();
      r.rotation_deg = r.rotation_std_deg = r.translation_m = r.translation_std_m =
          std::numeric_limits<double>::quiet_NaN();
    }
  }
  return records;
}

CalibrationResult ResultFromMessage(const extrinsic_t& e) {
  CalibrationResult r;
  r.T_camera_lidar = FromRowMajor(e.T_camera_lidar);
  r.covariance = Matrix6FromArray(e.covariance);
  r.status = ExtrinsicStatusName(e.status);
  r.observability = ObservabilityName(e.observability);
  for (int k = 0; k < e.num_used; ++k)
    r.motions_used.push_back(std::to_string(e.used_station_i[k]) + "-" + std::to_string(e.used_station_j[k]));
  for (int k = 0; k < e.num_rejected; ++k)
    r.motions_rejected.push_back(std::to_string(e.rejected_station_i[k]) + "-" +
                                 std::to_string(e.rejected_station_j[k]));
  r.residual_rms = e.residual_rms;
  const Eigen::Vector3d direction(e.unobservable_direction[0], e.unobservable_direction[1],
                                  e.unobservable_direction[2]);
  if (direction.allFinite() && direction.norm() > 0.5) r.unobservable_direction = direction.normalized();
  r.extra["version"] = std::to_string(e.version);
  r.extra["iterations"] = std::to_string(e.iteration);
  r.extra["scaled"] = e.scaled ? "true" : "false";
  if (!e.message.empty()) r.extra["message"] = e.message;
  r.changes = ChangeRecords(e);
  return r;
}

namespace {

// The reasons motions failed, most frequent first: what a user needs when no extrinsic came out.
std::string FailureReasonsText(const SessionRecord& session) {
  std::vector<std::pair<int, std::string>> reasons;
  for (const auto& [reason, count] : session.failure_reasons()) reasons.emplace_back(count, reason);
  std::sort(reasons.begin(), reasons.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::string text;
  for (size_t k = 0; k < reasons.size() && k < 3; ++k)
    text += (k ? "; " : "; failed motions: ") + reasons[k].second + " (" + std::to_string(reasons[k].first) + "x)";
  return text;
}

void WriteConvergence(const SessionRecord& session, const std::optional<Isometry3>& truth, const std::string& dir,
                      CalibrationOutputs* out) {
  const std::string csv = dir + "/convergence.csv";
  std::ostringstream file;
  file << "version,iteration,status,scaled,change_rotation_deg,change_translation_m,rot_err_deg,trans_err_m\n";
  for (const auto& e : session.extrinsics()) {
    file << e.version << "," << e.iteration << "," << ExtrinsicStatusName(e.status) << "," << (e.scaled ? 1 : 0) << ","
         << e.change_rotation_rad * 180.0 / M_PI << "," << e.change_translation_m << ",";
    if (truth) {
      const ExtrinsicError err = CompareExtrinsics(FromRowMajor(e.T_camera_lidar), *truth);
      file << err.rotation_deg << "," << err.translation_m << "\n";
    } else {
      file << ",\n";
    }
  }
  WriteFileChecked(csv, file.str());
  out->files.push_back(csv);
  const std::string png = dir + "/convergence.png";
  std::ostringstream script;
  script << "set terminal pngcairo size 900,500 noenhanced\nset output '" << png << "'\n"
         << "set datafile separator ','; set key outside bottom center; set key autotitle columnhead; set xlabel "
            "'extrinsic version';"
         << "set logscale y; set format y '%g'; set grid;";
  // Scaled estimates (the alternation) and scaleless ones apart; zero changes are not drawn.
  const std::string changes =
      "'' using 1:($5>0?$5:1/0) with points pt 2 title 'rotation change per iteration (deg)', "
      "'' using 1:($6>0?$6*100:1/0) with points pt 4 title 'translation change per iteration (cm)'";
  if (truth)
    script << "set ylabel 'error'; plot '" << csv
           << "' using 1:($4==1?$7:1/0) with linespoints title 'rotation error (deg)', "
           << "'' using 1:($4==1?$8*100:1/0) with linespoints title 'translation error (cm)', "
           << "'' using 1:($4==0?$8*100:1/0) with points pt 6 title 'scaleless translation error (cm)', " << changes;
  else
    script << "set ylabel 'change'; plot '" << csv << "' using 1:(1/0) notitle, " << changes;
  const std::string script_path = dir + "/convergence.gp";
  WriteFileChecked(script_path, script.str() + "\n");
  const std::string command = "gnuplot '" + script_path + "' 2>/dev/null";
  if (std::system(command.c_str()) == 0 && fs::exists(png))
    out->files.push_back(png);
  else
    out->warnings.push_back("convergence.png not drawn: gnuplot (Debian package gnuplot-nox) failed or is missing");
}

// One picture per held station, at most kMaxOverlays spread evenly over them (first and last included),
// drawn in parallel (they are independent).
constexpr int kMaxOverlays = 12;

void WriteOverlays(const SessionRecord& session, const Isometry3& X, const std::string& dir, CalibrationOutputs* out) {
  std::vector<const station_t*> held;
  for (const auto& [id, station] : session.kept_stations()) held.push_back(&station);
  std::vector<const station_t*> stations;
  const int n = static_cast<int>(held.size());
  for (int k = 0; k < std::min(n, kMaxOverlays); ++k)
    stations.push_back(held[n <= kMaxOverlays ? k : static_cast<int>(std::lround(k * (n - 1.0) / (kMaxOverlays - 1)))]);
  std::vector<std::string> files(stations.size()), warnings(stations.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (int k = 0; k < static_cast<int>(stations.size()); ++k) {
    const station_t& station = *stations[k];
    try {
      const cv::Mat image = ImageToMat(station.image);
      const PointCloud cloud = CloudFromMsg(station.cloud);
      const auto camera = MakeCameraModel(CameraFromMsg(station.camera));
      cv::Mat board = RenderCheckerboard(image, cloud, *camera, X, std::max(16, camera->width() / 24));
      cv::Mat depth = RenderDepthOverlay(image, cloud, *camera, X);
      cv::Mat both;
      cv::vconcat(board, depth, both);
      const std::string path = dir + "/overlay-" + std::to_string(station.id) + ".png";
      if (!cv::imwrite(path, both)) throw std::runtime_error(path + ": cannot write the PNG");
      files[k] = path;
    } catch (const std::exception& e) {
      warnings[k] = "overlay of station " + std::to_string(station.id) + ": " + e.what();
    }
  }
  for (size_t k = 0; k < stations.size(); ++k) {
    if (!files[k].empty()) out->files.push_back(files[k]);
    if (!warnings[k].empty()) out->warnings.push_back(warnings[k]);
  }
}

// Scan points with the colour of the pixel they project to, first station only when the others have
// no pose; binary little-endian PLY.
void WriteColoredCloud(const SessionRecord& session, const Isometry3& X, const std::string& dir,
                       CalibrationOutputs* out) {
  if (session.kept_stations().empty()) return;
  const station_t& station = session.kept_stations().begin()->second;
  try {
    const cv::Mat image = ImageToMat(station.image);
    cv::Mat bgr;
    if (image.channels() == 1)
      cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
    else
      bgr = image;
    const PointCloud cloud = CloudFromMsg(station.cloud);
    const auto camera = MakeCameraModel(CameraFromMsg(station.camera));
    std::vector<std::pair<Eigen::Vector3f, cv::Vec3b>> points;
    for (const auto& p : cloud.points) {
      if (!p.allFinite()) continue;
      Eigen::Vector2d px;
      if (!camera->Project(X * p.cast<double>(), &px)) continue;
      const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
      if (u < 0 || v < 0 || u >= bgr.cols || v >= bgr.rows) continue;
      points.emplace_back(p, bgr.at<cv::Vec3b>(v, u));
    }
    const std::string path = dir + "/colored_cloud.ply";
    std::ostringstream file;
    file << "ply\nformat binary_little_endian 1.0\ncomment fusecal: station " << station.id
         << " coloured through the estimated extrinsic\nelement vertex " << points.size()
         << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
         << "property uchar blue\nend_header\n";
    for (const auto& [p, c] : points) {
      file.write(reinterpret_cast<const char*>(p.data()), 12);
      const uint8_t rgb[3] = {c[2], c[1], c[0]};
      file.write(reinterpret_cast<const char*>(rgb), 3);
    }
    WriteFileChecked(path, file.str());
    out->files.push_back(path);
  } catch (const std::exception& e) {
    out->warnings.push_back(std::string("colored_cloud.ply: ") + e.what());
  }
}

}  // namespace

CalibrationOutputs WriteCalibrationOutputs(const SessionRecord& session, const std::string& dir) {
  CalibrationOutputs out;
  fs::create_directories(dir);
  std::optional<Isometry3> truth;
  if (session.ground_truth()) truth = FromRowMajor(session.ground_truth()->T_camera_lidar);
  const extrinsic_t* final_message = session.Final();
  if (final_message) {
    out.has_result = true;
    out.final_result = ResultFromMessage(*final_message);
    const extrinsic_t* initial = session.Initial();
    if (initial) out.initial_result = ResultFromMessage(*initial);
    if (truth) {
      out.final_error = CompareExtrinsics(out.final_result.T_camera_lidar, *truth);
      if (out.final_result.unobservable_direction)
        out.observable_error =
            CompareObservablePart(out.final_result.T_camera_lidar, *truth, *out.final_result.unobservable_direction);
      if (initial) out.initial_error = CompareExtrinsics(out.initial_result.T_camera_lidar, *truth);
    }
  } else {
    out.final_result.status = Name(HandEyeStatus::kFailed);
    out.final_result.observability = session.stations().size() < 3 ? Name(Observability::kTooFewMotions) : "unknown";
    out.final_result.extra["message"] = "no extrinsic was estimated: " + std::to_string(session.stations().size()) +
                                        " stations, " + std::to_string(session.lidar_motions()) + " LiDAR and " +
                                        std::to_string(session.camera_motions()) + " camera motions" +
                                        FailureReasonsText(session);
  }
  // A file that cannot be written is a warning, not the end: the summary still shows the result.
  const std::string yaml = dir + "/extrinsic.yaml";
  try {
    WriteResultFile(yaml, out.final_result, session.Initial() ? &out.initial_result : nullptr);
    out.files.push_back(yaml);
    out.result_file_written = true;
  } catch (const std::exception& e) {
    out.warnings.push_back(std::string("the result file was not written: ") + e.what());
  }
  try {
    WriteConvergence(session, truth, dir, &out);
  } catch (const std::exception& e) {
    out.warnings.push_back(e.what());
  }
  if (out.has_result) {
    WriteOverlays(session, out.final_result.T_camera_lidar, dir, &out);
    WriteColoredCloud(session, out.final_result.T_camera_lidar, dir, &out);
  }
  return out;
}

std::string SummaryText(const CalibrationOutputs& o, const std::string& dir) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(4);
  const auto& r = o.final_result;
  s << "result: " << r.status << " (observability: " << r.observability << ")\n";
  if (o.has_result) {
    const Eigen::Vector3d t = r.T_camera_lidar.translation();
    const Eigen::Vector3d rpy = RpyFromRotation(r.T_camera_lidar.linear()) * 180.0 / M_PI;
    s << "T_camera_lidar: t = [" << t.x() << ", " << t.y() << ", " << t.z() << "] m, rpy = [" << rpy.x() << ", "
      << rpy.y() << ", " << rpy.z() << "] deg\n";
    if (r.covariance) {
      const Eigen::Vector3d sr = RotationStdDevDeg(*r.covariance), st = TranslationStdDevM(*r.covariance);
      s << "std dev: rotation [" << sr.x() << ", " << sr.y() << ", " << sr.z() << "] deg, translation [" << st.x()
        << ", " << st.y() << ", " << st.z() << "] m\n";
    }
  }
  if (o.final_error)
    s << "error vs ground truth: rotation " << o.final_error->rotation_deg << " deg, translation "
      << o.final_error->translation_m * 100 << " cm\n";
  if (o.observable_error) {
    const Eigen::Vector3d& d = *r.unobservable_direction;
    s << "observable part vs ground truth: the LiDAR directions seen along camera [" << d.x() << ", " << d.y() << ", "
      << d.z() << "] differ by " << o.observable_error->direction_deg << " deg";
    if (r.observability == Name(Observability::kTranslationPartlyUnobservable))
      s << "; translation perpendicular to it " << o.observable_error->translation_perpendicular_m.norm() * 100
        << " cm";
    s << "\n";
  }
  if (o.initial_error)
    s << "scaleless initial estimate: rotation " << o.initial_error->rotation_deg << " deg, translation "
      << o.initial_error->translation_m * 100 << " cm\n";
  if (r.extra.count("message")) s << r.extra.at("message") << "\n";
  for (const auto& w : o.warnings) s << "warning: " << w << "\n";
  s << "outputs in " << dir
    << "/ (extrinsic.yaml, convergence.csv/png, overlay-*.png, colored_cloud.ply, session.lcmlog)\n";
  return s.str();
}

void AddOutputFile(CalibrationOutputs* outputs, const std::function<std::string()>& write) {
  try {
    outputs->files.push_back(write());
  } catch (const std::exception& e) {
    outputs->warnings.push_back(e.what());
  }
}

bool FinalConverged(const CalibrationOutputs& outputs) {
  return outputs.final_result.status == Name(HandEyeStatus::kConverged) && outputs.result_file_written;
}

RigOutputs WriteRigOutputs(const std::vector<const SessionRecord*>& sessions, const std::string& out_dir) {
  RigOutputs rig;
  std::vector<RigCameraResult> results;
  for (const SessionRecord* session : sessions) {
    const std::string dir = out_dir + "/" + session->camera();
    std::filesystem::create_directories(dir);
    CameraOutputs camera{session->camera(), WriteCalibrationOutputs(*session, dir)};
    if (camera.outputs.has_result) {
      RigCameraResult r;
      r.camera = camera.camera;
      r.T_camera_lidar = camera.outputs.final_result.T_camera_lidar;
      r.covariance = camera.outputs.final_result.covariance;
      r.status = camera.outputs.final_result.status;
      r.file = camera.camera + "/extrinsic.yaml";
      results.push_back(r);
    } else {
      rig.warnings.push_back("camera " + camera.camera + ": no result, so the rig's extrinsic.yaml leaves it out");
    }
    rig.cameras.push_back(std::move(camera));
  }
  if (results.empty()) return rig;
  rig.rig = MakeRigResult(std::move(results));
  const std::string path = out_dir + "/extrinsic.yaml";
  try {
    WriteRigFile(path, *rig.rig);
    rig.rig_file = path;
  } catch (const std::exception& e) {
    rig.warnings.push_back(e.what());
  }
  return rig;
}

std::string RigSummaryText(const RigOutputs& o, const std::string& out_dir) {
  std::ostringstream s;
  for (const auto& c : o.cameras)
    s << "camera " << c.camera << ": " << SummaryText(c.outputs, out_dir + "/" + c.camera);
  if (o.rig) {
    s << std::fixed << std::setprecision(4);
    for (const auto& c : o.rig->camera_to_camera) {
      const Eigen::Vector3d t = c.T.translation();
      s << "T_" << c.to << "_" << c.from << ": t = [" << t.x() << ", " << t.y() << ", " << t.z() << "] m, angle "
        << RotationAngle(c.T.linear()) * 180.0 / M_PI << " deg";
      if (c.covariance)
        s << ", std dev rotation " << RotationStdDevDeg(*c.covariance).maxCoeff() << " deg, translation "
          << TranslationStdDevM(*c.covariance).maxCoeff() << " m (largest)";
      s << "\n";
    }
  }
  for (const auto& w : o.warnings) s << "warning: " << w << "\n";
  if (o.rig_file) s << "rig: " << *o.rig_file << " (every T_<camera>_lidar, camera to camera)\n";
  return s.str();
}

bool AllConverged(const RigOutputs& o) {
  if (o.cameras.empty() || !o.rig_file) return false;
  for (const auto& c : o.cameras)
    if (!FinalConverged(c.outputs)) return false;
  return true;
}

std::string RigProgressText(const std::vector<const SessionRecord*>& sessions) {
  std::string text = ProgressText(*sessions.front());
  if (sessions.size() == 1) return text;
  text = sessions.front()->camera() + ": " + text;
  for (size_t k = 1; k < sessions.size(); ++k) {
    const extrinsic_t* e = sessions[k]->Final();
    text += " | " + sessions[k]->camera() + ": " +
            (e ? "v" + std::to_string(e->version) + " " + ExtrinsicStatusName(e->status) : std::string("no estimate"));
  }
  return text;
}

}  // namespace fusecal
