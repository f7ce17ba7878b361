// `fusecal import kitti|folder|ishikawa DIR --out LOG ...`, `fusecal import rosbag BAG --out LOG ...`.
#include <CLI/CLI.hpp>
#include <iostream>

#include "commands.hpp"
#include "progress.hpp"
#include "runtime/io/importers/folder.hpp"
#include "runtime/io/importers/ishikawa.hpp"
#include "runtime/io/importers/kitti.hpp"
#include "runtime/io/importers/rosbag.hpp"
#include "stages/formats/camera_file.hpp"

namespace fusecal {

namespace {

int Report(const std::string& out, const std::function<ImportReport()>& run) {
  try {
    const ImportReport report = run();
    for (const auto& w : report.warnings) std::cerr << "fusecal import: warning: " << w << "\n";
    std::cout << "wrote " << out << ": " << report.images << " images, " << report.scans << " scans, "
              << report.stations << " stations" << (report.warnings.empty() ? "" : " (see warnings)") << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "fusecal import: " << e.what() << " (no log written)\n";
    return 1;
  }
}

void AddRosbagImport(CLI::App& import, int* exit_code) {
  auto* rosbag = import.add_subcommand(
      "rosbag", "ROS 1 or ROS 2 bag: sensor_msgs Image/CompressedImage, PointCloud2 (or Livox CustomMsg), CameraInfo");
  static std::string bag_path, bag_out, bag_camera;
  static RosbagImportOptions options;
  rosbag->add_option("BAG", bag_path, "a ROS 1 .bag, or a ROS 2 bag folder, .mcap or .db3")->required();
  rosbag->add_option("--image-topic", options.image_topic, "sensor_msgs/Image or CompressedImage topic");
  rosbag->add_option("--cloud-topic", options.cloud_topic,
                     "sensor_msgs/PointCloud2 or livox_ros_driver2/CustomMsg topic");
  rosbag->add_option("--camera", bag_camera, "camera YAML, used instead of the bag's CameraInfo");
  rosbag->add_option("--camera-info-topic", options.camera_info_topic,
                     "CameraInfo topic (default: camera_info next to the image topic)");
  rosbag->add_option("--out", bag_out, "LCM log to write")->required();
  rosbag->callback([exit_code] {
    ProgressLine progress("importing " + bag_path);
    *exit_code = Report(bag_out, [&] {
      if (!bag_camera.empty()) options.camera = LoadCameraFile(bag_camera);
      return ImportRosbag(bag_path, bag_out, options, std::ref(progress));
    });
  });
}

}  // namespace

void AddImportCommands(CLI::App& app, int* exit_code) {
  auto* import = app.add_subcommand("import", "turn a dataset into an LCM log");
  import->require_subcommand(1);

  auto* kitti = import->add_subcommand("kitti", "KITTI raw drive folder (image_02, velodyne_points, calib_*)");
  static std::string kitti_dir, kitti_out, stations = "none";
  kitti->add_option("DIR", kitti_dir)->required()->check(CLI::ExistingDirectory);
  kitti->add_option("--out", kitti_out, "LCM log to write")->required();
  kitti->add_option("--stations", stations, "none, or every:N to also write a STATION every N frames");
  kitti->callback([exit_code] {
    KittiImportOptions options;
    if (stations.rfind("every:", 0) == 0) {
      try {
        options.station_every = std::stoi(stations.substr(6));
      } catch (const std::exception&) {
      }
    }
    if (stations != "none" && options.station_every <= 0) {
      std::cerr << "fusecal import kitti: --stations must be 'none' or 'every:N' with N >= 1\n";
      *exit_code = 2;
      return;
    }
    ProgressLine progress("importing " + kitti_dir);
    *exit_code = Report(kitti_out, [&] { return ImportKitti(kitti_dir, kitti_out, options, std::ref(progress)); });
  });

  auto* folder = import->add_subcommand("folder", "images and scans paired by file name, one station each");
  static std::string folder_dir, folder_out, camera_path;
  folder->add_option("DIR", folder_dir)->required()->check(CLI::ExistingDirectory);
  folder->add_option("--camera", camera_path, "camera YAML")->required();
  folder->add_option("--out", folder_out, "LCM log to write")->required();
  folder->callback([exit_code] {
    ProgressLine progress("importing " + folder_dir);
    *exit_code = Report(folder_out, [&] {
      return ImportFolder(folder_dir, LoadCameraFile(camera_path), folder_out, std::ref(progress));
    });
  });

  auto* ishikawa = import->add_subcommand("ishikawa", "the paper authors' dataset layout (position<N>.ply/.jpg)");
  static std::string ishikawa_dir, ishikawa_out;
  ishikawa->add_option("DIR", ishikawa_dir)->required()->check(CLI::ExistingDirectory);
  ishikawa->add_option("--out", ishikawa_out, "LCM log to write")->required();
  ishikawa->callback([exit_code] {
    ProgressLine progress("importing " + ishikawa_dir);
    *exit_code = Report(ishikawa_out, [&] { return ImportIshikawa(ishikawa_dir, ishikawa_out, std::ref(progress)); });
  });
  AddRosbagImport(*import, exit_code);
}

}  // namespace fusecal
