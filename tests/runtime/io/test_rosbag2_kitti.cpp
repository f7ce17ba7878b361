// Real data: the first frames of the KITTI snippet (../shared, read in place) written as ROS bags by
// write_kitti_bags (MCAP with zstd, lz4 and no compression, sqlite3 in a bag folder, ROS 1) import to the
// scans, images, stamps and intrinsics that `fusecal import kitti` gives for the same frames, with the
// images raw (rgb8) and PNG-compressed.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>

#include "fusecal/camera_info_t.hpp"
#include "fusecal/image_t.hpp"
#include "fusecal/point_cloud_t.hpp"
#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/formats/conversions.hpp"
#include "tests/support/process_utils.hpp"

namespace fusecal {
namespace {

namespace fs = std::filesystem;
using testing::RunCommand;

const std::string kKittiDir = KITTI_SNIPPET_DIR;
const std::string kFusecal = FUSECAL_BIN;
constexpr size_t kFrames = 8;

// The first `frames` lines of a timestamps.txt and links to the first `frames` data files.
void LinkFirstFrames(const fs::path& from, const fs::path& to, size_t frames) {
  fs::create_directories(to / "data");
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(from / "data")) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  for (size_t i = 0; i < frames && i < files.size(); ++i)
    fs::create_symlink(files[i], to / "data" / files[i].filename());
  std::ifstream in(from / "timestamps.txt");
  std::ofstream out(to / "timestamps.txt");
  std::string line;
  for (size_t i = 0; i < frames && std::getline(in, line); ++i) out << line << "\n";
}

struct ImportedLog {
  std::vector<CameraParams> cameras;
  std::vector<std::pair<int64_t, cv::Mat>> images;
  std::vector<std::pair<int64_t, PointCloud>> scans;
};

ImportedLog ReadImported(const std::string& path) {
  ImportedLog log;
  LogReader reader(path);
  while (auto event = reader.Next()) {
    const int size = static_cast<int>(event->data.size());
    if (event->channel == channels::kCameraInfo.name) {
      camera_info_t msg{};
      EXPECT_GE(msg.decode(event->data.data(), 0, size), 0);
      log.cameras.push_back(CameraFromMsg(msg));
    } else if (event->channel == channels::kCameraImage.name) {
      image_t msg{};
      EXPECT_GE(msg.decode(event->data.data(), 0, size), 0);
      log.images.emplace_back(msg.utime, ImageToMat(msg));
    } else if (event->channel == channels::kLidarScan.name) {
      point_cloud_t msg{};
      EXPECT_GE(msg.decode(event->data.data(), 0, size), 0);
      log.scans.emplace_back(msg.utime, CloudFromMsg(msg));
    }
  }
  EXPECT_TRUE(reader.problems().empty()) << path;
  return log;
}

void ExpectSameFrames(const ImportedLog& expected, const ImportedLog& got) {
  ASSERT_EQ(got.cameras.size(), 1u);
  const CameraParams &a = expected.cameras.at(0), &b = got.cameras.at(0);
  EXPECT_EQ(b.model, a.model);
  EXPECT_EQ(b.width, a.width);
  EXPECT_EQ(b.height, a.height);
  EXPECT_EQ(b.fx, a.fx);
  EXPECT_EQ(b.fy, a.fy);
  EXPECT_EQ(b.cx, a.cx);
  EXPECT_EQ(b.cy, a.cy);
  EXPECT_EQ(b.dist, a.dist);
  ASSERT_EQ(got.images.size(), expected.images.size());
  for (size_t i = 0; i < got.images.size(); ++i) {
    SCOPED_TRACE("image " + std::to_string(i));
    EXPECT_EQ(got.images[i].first, expected.images[i].first);
    ASSERT_EQ(got.images[i].second.size(), expected.images[i].second.size());
    ASSERT_EQ(got.images[i].second.type(), expected.images[i].second.type());
    EXPECT_EQ(cv::norm(got.images[i].second, expected.images[i].second, cv::NORM_INF), 0.0);
  }
  ASSERT_EQ(got.scans.size(), expected.scans.size());
  for (size_t i = 0; i < got.scans.size(); ++i) {
    SCOPED_TRACE("scan " + std::to_string(i));
    EXPECT_EQ(got.scans[i].first, expected.scans[i].first);
    EXPECT_GT(got.scans[i].second.points.size(), 100000u);
    EXPECT_TRUE(got.scans[i].second.points == expected.scans[i].second.points);
    EXPECT_TRUE(got.scans[i].second.intensity == expected.scans[i].second.intensity);
  }
}

TEST(KittiRosbag2, EveryBagImportsToTheFramesOfTheDataset) {
  if (!fs::exists(kKittiDir + "/calib_velo_to_cam.txt"))
    GTEST_SKIP() << "KITTI snippet not found at " << kKittiDir << ": real-data check not run";
  const fs::path dir = ::testing::TempDir() + "fusecal_kitti_rosbag2_" + std::to_string(getpid());
  fs::remove_all(dir);
  const fs::path kitti = dir / "kitti";
  fs::create_directories(kitti);
  for (const char* calib : {"calib_velo_to_cam.txt", "calib_cam_to_cam.txt"})
    fs::copy_file(kKittiDir + "/" + calib, kitti / calib);
  LinkFirstFrames(kKittiDir + "/image_02", kitti / "image_02", kFrames);
  LinkFirstFrames(kKittiDir + "/velodyne_points", kitti / "velodyne_points", kFrames);

  const std::string dataset_log = (dir / "dataset.lcmlog").string();
  const auto imported = RunCommand(kFusecal + " import kitti " + kitti.string() + " --out " + dataset_log + " 2>&1");
  ASSERT_EQ(imported.exit_code, 0) << imported.output;
  const ImportedLog expected = ReadImported(dataset_log);
  ASSERT_EQ(expected.images.size(), kFrames);
  ASSERT_EQ(expected.scans.size(), kFrames);

  const auto written =
      RunCommand(std::string(WRITE_KITTI_BAGS_BIN) + " " + kitti.string() + " " + (dir / "bags").string() + " 2>&1");
  ASSERT_EQ(written.exit_code, 0) << written.output;
  for (const std::string bag :
       {"kitti_mcap-zstd.mcap", "kitti_mcap-lz4.mcap", "kitti_mcap-none.mcap", "kitti_db3", "kitti_ros1.bag"}) {
    for (const std::string image_topic :
         {"/kitti/camera_color_left/image_raw", "/kitti/camera_color_left/image_raw/compressed"}) {
      SCOPED_TRACE(bag + " " + image_topic);
      const std::string log = (dir / "bag.lcmlog").string();
      const auto run = RunCommand(kFusecal + " import rosbag " + (dir / "bags" / bag).string() + " --image-topic " +
                                  image_topic + " --cloud-topic /kitti/velo/pointcloud --out " + log + " 2>&1");
      ASSERT_EQ(run.exit_code, 0) << run.output;
      EXPECT_EQ(run.output.find("warning"), std::string::npos) << run.output;
      EXPECT_NE(run.output.find(std::to_string(kFrames) + " images, " + std::to_string(kFrames) + " scans"),
                std::string::npos)
          << run.output;
      ExpectSameFrames(expected, ReadImported(log));
    }
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace fusecal
