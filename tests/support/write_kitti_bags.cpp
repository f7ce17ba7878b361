// The KITTI raw snippet as ROS bags, the way a recorder on the car would have written it: for each frame
// a CameraInfo, the colour image raw (rgb8) and PNG-compressed (the dataset's own file), and the Velodyne
// scan as a PointCloud2 whose data are the .bin file's bytes (x, y, z, intensity as float32). Header
// stamps are the dataset's timestamps; arrival times trail them as a driver's would.
//
//   write_kitti_bags KITTI_DIR OUT_DIR [--formats mcap-zstd,mcap-lz4,mcap-none,db3,ros1] [--frames N]
//
// writes OUT_DIR/kitti_mcap-zstd.mcap, kitti_mcap-lz4.mcap, kitti_mcap-none.mcap (chunked, uncompressed),
// kitti_db3/ (a rosbag2 folder: metadata.yaml and kitti_db3_0.db3) and kitti_ros1.bag.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "runtime/io/importers/kitti.hpp"
#include "stages/formats/ros_sensor_encode.hpp"
#include "tests/support/db3_test_writer.hpp"
#include "tests/support/recorded_bags.hpp"
#include "tests/support/ros1_bag_writer.hpp"

namespace fusecal {
namespace {

namespace fs = std::filesystem;
using testing::RecordedMessage;

const std::string kCameraInfoTopic = "/kitti/camera_color_left/camera_info";
const std::string kImageTopic = "/kitti/camera_color_left/image_raw";
const std::string kCompressedTopic = "/kitti/camera_color_left/image_raw/compressed";
const std::string kCloudTopic = "/kitti/velo/pointcloud";

std::vector<uint8_t> ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

// data/*.<extension> in name order, each with its line of timestamps.txt.
std::vector<std::pair<fs::path, int64_t>> SensorFiles(const fs::path& sensor_dir, const std::string& extension) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(sensor_dir / "data"))
    if (entry.path().extension() == extension) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  const std::vector<int64_t> times = ReadKittiTimestamps((sensor_dir / "timestamps.txt").string());
  if (times.size() != files.size())
    throw std::runtime_error((sensor_dir / "timestamps.txt").string() + " has " + std::to_string(times.size()) +
                             " lines for " + std::to_string(files.size()) + " files");
  std::vector<std::pair<fs::path, int64_t>> out;
  for (size_t i = 0; i < files.size(); ++i) out.emplace_back(files[i], times[i]);
  return out;
}

RosHeader Header(int64_t utime, const std::string& frame_id) { return RosHeader{UtimeToRosStamp(utime), frame_id}; }

std::vector<RecordedMessage> Recording(const fs::path& kitti, size_t frames) {
  const KittiCalibration calib = ReadKittiCalibration(kitti.string());
  const auto images = SensorFiles(kitti / "image_02", ".png");
  const auto scans = SensorFiles(kitti / "velodyne_points", ".bin");
  std::vector<RecordedMessage> recording;
  for (size_t i = 0; i < std::min(frames, images.size()); ++i) {
    const auto& [path, utime] = images[i];
    std::vector<uint8_t> png = ReadFile(path);
    cv::Mat rgb = cv::imdecode(png, cv::IMREAD_COLOR);
    if (rgb.empty()) throw std::runtime_error(path.string() + ": not a PNG");
    cv::cvtColor(rgb, rgb, cv::COLOR_BGR2RGB);
    RosImage raw;
    raw.header = Header(utime, "camera_color_left");
    raw.width = static_cast<uint32_t>(rgb.cols);
    raw.height = static_cast<uint32_t>(rgb.rows);
    raw.encoding = "rgb8";
    raw.step = raw.width * 3;
    raw.data.assign(rgb.data, rgb.data + rgb.total() * 3);
    RosCompressedImage compressed;
    compressed.header = raw.header;
    compressed.format = "rgb8; png compressed bgr8";
    compressed.data = std::move(png);
    recording.push_back(
        {kCameraInfoTopic, utime + 2000, ToRosCameraInfo(calib.camera, Header(utime, "camera_color_left")), {}});
    recording.push_back({kImageTopic, utime + 15000, std::move(raw), {}});
    recording.push_back({kCompressedTopic, utime + 20000, std::move(compressed), {}});
  }
  for (size_t i = 0; i < std::min(frames, scans.size()); ++i) {
    const auto& [path, utime] = scans[i];
    RosPointCloud2 cloud;
    cloud.header = Header(utime, "velo_link");
    cloud.data = ReadFile(path);
    if (cloud.data.size() % 16 != 0) throw std::runtime_error(path.string() + ": not a whole number of points");
    cloud.height = 1;
    cloud.width = static_cast<uint32_t>(cloud.data.size() / 16);
    cloud.fields = {{"x", 0, RosPointField::FLOAT32, 1},
                    {"y", 4, RosPointField::FLOAT32, 1},
                    {"z", 8, RosPointField::FLOAT32, 1},
                    {"intensity", 12, RosPointField::FLOAT32, 1}};
    cloud.point_step = 16;
    cloud.row_step = static_cast<uint32_t>(cloud.data.size());
    cloud.is_dense = true;
    recording.push_back({kCloudTopic, utime + 40000, std::move(cloud), {}});
  }
  std::stable_sort(recording.begin(), recording.end(), [](const RecordedMessage& a, const RecordedMessage& b) {
    return a.arrival_utime < b.arrival_utime;
  });
  return recording;
}

void WriteBag(const std::string& format, const std::vector<RecordedMessage>& recording, const fs::path& out) {
  if (format == "ros1") return testing::WriteRos1Bag((out / "kitti_ros1.bag").string(), recording);
  if (format == "db3") {
    const fs::path folder = out / "kitti_db3";
    fs::remove_all(folder);
    fs::create_directories(folder);
    testing::WriteDb3Bag((folder / "kitti_db3_0.db3").string(), recording);
    std::vector<testing::BagTopic> topics;
    std::vector<testing::BagMessage> messages;
    testing::ToRos2Bag(recording, topics, messages);
    return testing::WriteRosbag2Metadata(folder.string(), "sqlite3", {"kitti_db3_0.db3"}, topics, messages);
  }
  testing::McapWriteOptions options;
  options.messages_per_chunk = 8;  // a chunk of a few MB, as rosbag2's default chunk size gives
  if (format == "mcap-zstd")
    options.compression = "zstd";
  else if (format == "mcap-lz4")
    options.compression = "lz4";
  else if (format == "mcap-none")
    options.compression = "";
  else
    throw std::runtime_error("unknown format '" + format + "' (mcap-zstd, mcap-lz4, mcap-none, db3, ros1)");
  testing::WriteMcapBag((out / ("kitti_" + format + ".mcap")).string(), recording, options);
}

}  // namespace
}  // namespace fusecal

int main(int argc, char** argv) {
  CLI::App app("The KITTI raw snippet as ROS 2 bags (MCAP, sqlite3) and a ROS 1 bag");
  std::string kitti, out, formats = "mcap-zstd,mcap-lz4,mcap-none,db3,ros1";
  size_t frames = 1000000;
  app.add_option("KITTI_DIR", kitti, "KITTI raw drive folder (image_02, velodyne_points, calib_*)")
      ->required()
      ->check(CLI::ExistingDirectory);
  app.add_option("OUT_DIR", out, "folder for the bags (created)")->required();
  app.add_option("--formats", formats, "comma-separated: mcap-zstd, mcap-lz4, mcap-none, db3, ros1");
  app.add_option("--frames", frames, "the first N frames only")->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  try {
    std::filesystem::create_directories(out);
    const auto recording = fusecal::Recording(kitti, frames);
    std::stringstream list(formats);
    for (std::string format; std::getline(list, format, ',');) {
      std::cerr << "write_kitti_bags: " << format << " (" << recording.size() << " messages)\n";
      fusecal::WriteBag(format, recording, out);
    }
  } catch (const std::exception& e) {
    std::cerr << "write_kitti_bags: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
