// One stage core on files, for checking a single step by hand:
//   fusecal register SCAN_A SCAN_B [--config]          LiDAR motion T_a_b (ICP, no initial guess)
//   fusecal camera-motion IMG_A IMG_B --camera FILE     scaleless camera motion
//   fusecal fusion-motion --scan --image-i --image-j --camera --extrinsic   metric camera motion
//   fusecal stations LOG [--config] [--trace]           the stations the detector finds in a recording
// Each prints one JSON line.
#include <CLI/CLI.hpp>
#include <cmath>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "commands.hpp"
#include "fusecal/camera_info_t.hpp"
#include "fusecal/image_t.hpp"
#include "fusecal/point_cloud_t.hpp"
#include "runtime/channels.hpp"
#include "runtime/io/scan_io/scan_io.hpp"
#include "runtime/lcm_log.hpp"
#include "runtime/pipeline/pipeline_config.hpp"
#include "stages/formats/camera_file.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/message_json.hpp"
#include "stages/formats/result_file.hpp"

namespace fusecal {

namespace {

std::vector<double> RowMajor(const Isometry3& T) {
  std::vector<double> m(16);
  ToRowMajor(T, m.data());
  return m;
}

cv::Mat ReadImage(const std::string& path) {
  cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error(path + ": cannot read the image (missing, corrupt or unknown format)");
  return image;
}

// Runs `body` and turns exceptions into a message and exit status 1.
void Guard(const std::string& name, int* exit_code, const std::function<int()>& body) {
  try {
    *exit_code = body();
  } catch (const std::exception& e) {
    std::cerr << "fusecal " << name << ": " << e.what() << "\n";
    *exit_code = 1;
  }
}

PipelineConfig ConfigOrDefault(const std::string& path) {
  return LoadPipelineConfig(path.empty() ? DefaultPipelineConfigPath() : path);
}

void AddRegisterCommand(CLI::App& app, int* exit_code) {
  static std::string scan_a, scan_b, register_config;
  auto* reg = app.add_subcommand("register", "LiDAR motion between two scans, no initial guess");
  reg->add_option("SCAN_A", scan_a, "scan (.bin, .pcd, .ply)")->required();
  reg->add_option("SCAN_B", scan_b, "scan (.bin, .pcd, .ply)")->required();
  reg->add_option("--config", register_config, "pipeline config (its lidar_icp section)");
  reg->callback([exit_code] {
    Guard("register", exit_code, [] {
      const auto settings = ConfigOrDefault(register_config).lidar_icp.registration;
      const PointCloud a = ReadScan(scan_a);  // in order, so that a missing file is named first
      const PointCloud b = ReadScan(scan_b);
      const auto r = lidar_icp::Register(a, b, settings);
      OrderedJson line{{"T_a_b", RowMajor(r.T_li_lj)},
                       {"converged", r.usable()},
                       {"fitness", r.fitness},
                       {"rmse_m", r.inlier_rms_m},
                       {"seconds", r.seconds}};
      if (!r.usable()) line["reason"] = r.failure_reason.text;
      std::cout << line.dump() << "\n";
      if (!r.usable())
        std::cerr << "fusecal register: " << scan_a << " -> " << scan_b << ": " << r.failure_reason.text << "\n";
      return r.usable() ? 0 : 1;
    });
  });
}

void AddCameraMotionCommand(CLI::App& app, int* exit_code) {
  static std::string image_a, image_b, camera_path;
  auto* cam = app.add_subcommand("camera-motion", "scaleless camera motion between two images");
  cam->add_option("IMG_A", image_a)->required();
  cam->add_option("IMG_B", image_b)->required();
  cam->add_option("--camera", camera_path, "camera YAML")->required();
  cam->callback([exit_code] {
    Guard("camera-motion", exit_code, [] {
      const auto camera = MakeCameraModel(LoadCameraFile(camera_path));
      const cv::Mat a = ReadImage(image_a);
      const cv::Mat b = ReadImage(image_b);
      const auto r = EstimateRelativePose(a, b, *camera);
      std::vector<double> R(9), t{r.t_unit.x(), r.t_unit.y(), r.t_unit.z()};
      for (int i = 0; i < 9; ++i) R[i] = r.R(i / 3, i % 3);
      std::vector<std::string> flags;
      if (r.too_few_inliers) flags.push_back("too_few_inliers");
      if (r.translation_unreliable) flags.push_back("translation_unreliable");
      OrderedJson line{{"R", R}, {"t_unit", t}, {"inliers", r.inliers}, {"flags", flags}, {"seconds", r.seconds}};
      if (!r.failure_reason.text.empty()) line["reason"] = r.failure_reason.text;
      std::cout << line.dump() << "\n";
      return r.valid ? 0 : 1;
    });
  });
}

void AddFusionMotionCommand(CLI::App& app, int* exit_code) {
  static std::string fm_scan, fm_image_i, fm_image_j, fm_camera, fm_extrinsic;
  auto* fm = app.add_subcommand("fusion-motion", "metric camera motion from LiDAR depth and tracking");
  fm->add_option("--scan", fm_scan, "scan of station i")->required();
  fm->add_option("--image-i", fm_image_i, "image of station i")->required();
  fm->add_option("--image-j", fm_image_j, "image of station j")->required();
  fm->add_option("--camera", fm_camera, "camera YAML")->required();
  fm->add_option("--extrinsic", fm_extrinsic, "result file with T_camera_lidar")->required();
  fm->callback([exit_code] {
    Guard("fusion-motion", exit_code, [] {
      const auto camera = MakeCameraModel(LoadCameraFile(fm_camera));
      const Isometry3 X = ReadResultFile(fm_extrinsic).T_camera_lidar;
      const auto r = fusion_odometry::EstimateScaledMotion(ReadScan(fm_scan), ReadImage(fm_image_i),
                                                           ReadImage(fm_image_j), *camera, X);
      OrderedJson line{
          {"T_i_j", RowMajor(r.T_ci_cj)}, {"converged", r.usable()}, {"inliers", r.inliers}, {"seconds", r.seconds}};
      if (!r.usable()) line["reason"] = r.failure_reason.text;
      std::cout << line.dump() << "\n";
      return r.usable() ? 0 : 1;
    });
  });
}

// One JSON line of what the detector makes of the frame it was just given (--trace).
void PrintTrace(const char* sensor, int64_t utime, const StationarityState& st) {
  const auto number = [](double v) { return std::isfinite(v) ? OrderedJson(v) : OrderedJson(nullptr); };
  std::cout << OrderedJson{{"frame", sensor},
                           {"utime", utime},
                           {"phase", ToString(st.phase)},
                           {"image_still", st.image_still},
                           {"lidar_still", st.lidar_still},
                           {"image_flow_px", number(st.image_flow_px)},
                           {"image_drift_px", number(st.image_drift_px)},
                           {"lidar_change_m", number(st.lidar_change_m)},
                           {"lidar_drift_m", number(st.lidar_drift_m)},
                           {"lidar_common_cells", st.lidar_common_cells},
                           {"reason", st.reason}}
                   .dump()
            << "\n";
}

// Feeds the log's images and scans to the detector and prints each station as one JSON line (and, with
// trace, the detector's state after every frame).
int PrintStations(const std::string& log, const std::string& config, bool trace) {
  StationarityDetector detector(ConfigOrDefault(config).stationarity.detector);
  auto print = [](const DetectedStation& s) {
    std::cout << OrderedJson{{"id", s.id},
                             {"utime", s.utime},
                             {"image_utime", s.image_utime},
                             {"scan_utime", s.scan_utime},
                             {"still_from", s.still_from},
                             {"still_to", s.still_to}}
                     .dump()
              << std::endl;
  };
  LogReader reader(log);
  int bad = 0;
  while (auto event = reader.Next()) {
    try {
      if (event->channel == channels::kCameraImage.name) {
        image_t msg{};
        if (msg.decode(event->data.data(), 0, static_cast<int>(event->data.size())) < 0)
          throw std::runtime_error("corrupt image_t");
        for (const auto& s : detector.AddImage(msg.utime, ImageToMat(msg))) print(s);
        if (trace) PrintTrace("image", msg.utime, detector.State());
      } else if (event->channel == channels::kLidarScan.name) {
        point_cloud_t msg{};
        if (msg.decode(event->data.data(), 0, static_cast<int>(event->data.size())) < 0)
          throw std::runtime_error("corrupt point_cloud_t");
        for (const auto& s : detector.AddScan(msg.utime, CloudFromMsg(msg))) print(s);
        if (trace) PrintTrace("scan", msg.utime, detector.State());
      }
    } catch (const std::exception& e) {
      if (bad++ < 5) std::cerr << "fusecal stations: event " << event->event_number << " skipped: " << e.what() << "\n";
    }
  }
  if (auto s = detector.Flush()) print(*s);
  for (const auto& problem : reader.problems()) std::cerr << "fusecal stations: " << problem << "\n";
  const auto state = detector.State();
  std::cerr << "fusecal stations: " << state.counters.images_received << " images, " << state.counters.scans_received
            << " scans, " << state.counters.stations_emitted << " stations\n";
  return reader.problems().empty() ? 0 : 1;
}

void AddStationsCommand(CLI::App& app, int* exit_code) {
  static std::string stations_log, stations_config;
  static bool stations_trace = false;
  auto* st = app.add_subcommand("stations", "the stops of a recording that become stations");
  st->add_option("LOG", stations_log, "LCM log with CAMERA_IMAGE and LIDAR_SCAN")->required();
  st->add_option("--config", stations_config, "pipeline config (its stationarity section)");
  st->add_flag("--trace", stations_trace,
               "also print the detector's state after every frame (image motion, LiDAR change, why not still)");
  st->callback([exit_code] {
    Guard("stations", exit_code, [] { return PrintStations(stations_log, stations_config, stations_trace); });
  });
}

}  // namespace

void AddStageCommands(CLI::App& app, int* exit_code) {
  AddRegisterCommand(app, exit_code);
  AddCameraMotionCommand(app, exit_code);
  AddFusionMotionCommand(app, exit_code);
  AddStationsCommand(app, exit_code);
}

}  // namespace fusecal
