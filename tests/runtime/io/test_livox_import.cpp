// `import rosbag` of Livox recordings we did not write (tests/runtime/io/livox_reference: ROS 1 by ROS's own
// Python bag writer, MCAP by the MCAP project's writer, sqlite3 by sql.js, the ROS 2 messages serialized
// by Foxglove's CDR serializer). Each bag holds three scans as livox_ros_driver2 CustomMsg and as the
// driver's PointCloud2: both import to the same points, intensities, rings and time offsets, which are
// those of frames.json; the two garbled CustomMsgs are skipped with a clear warning and the rest imports.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "runtime/channels.hpp"
#include "runtime/io/importers/rosbag.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/formats/conversions.hpp"
#include "tests/support/point_cloud_expectations.hpp"

namespace fusecal {
namespace {

namespace fs = std::filesystem;

const std::string kReference = LIVOX_REFERENCE_DIR;

struct Scan {
  int64_t utime = 0;
  PointCloud cloud;
};

std::vector<Scan> ReadScans(const std::string& log) {
  std::vector<Scan> scans;
  LogReader reader(log);
  while (auto event = reader.Next()) {
    if (event->channel != channels::kLidarScan.name) continue;
    point_cloud_t msg;
    EXPECT_GT(msg.decode(event->data.data(), 0, static_cast<int>(event->data.size())), 0);
    scans.push_back({event->utime, CloudFromMsg(msg)});
  }
  return scans;
}

struct Imported {
  ImportReport report;
  std::vector<Scan> scans;
};

Imported Import(const std::string& bag, const std::string& cloud_topic) {
  RosbagImportOptions options;
  options.image_topic = "/camera/image_raw";
  options.cloud_topic = cloud_topic;
  CameraParams camera;
  camera.width = 8;
  camera.height = 6;
  camera.fx = camera.fy = 10;
  camera.cx = 4;
  camera.cy = 3;
  options.camera = camera;
  const std::string log = (fs::temp_directory_path() /
                           ("livox-" + std::to_string(getpid()) + "-" + fs::path(bag).filename().string() + ".lcmlog"))
                              .string();
  Imported imported;
  imported.report = ImportRosbag(kReference + "/" + bag, log, options);
  imported.scans = ReadScans(log);
  fs::remove(log);
  return imported;
}

// The points of frames.json with a return, as the conversion keeps them.
std::vector<PointCloud> ExpectedClouds() {
  std::ifstream file(kReference + "/frames.json");
  const nlohmann::json frames = nlohmann::json::parse(file);
  std::vector<PointCloud> clouds;
  for (const auto& scan : frames.at("scans")) {
    PointCloud cloud;
    for (const auto& p : scan.at("points")) {
      if (p[1].is_null()) continue;  // NaN
      const Eigen::Vector3f xyz(p[1].get<float>(), p[2].get<float>(), p[3].get<float>());
      if (xyz.squaredNorm() == 0) continue;
      cloud.points.push_back(xyz);
      cloud.intensity.push_back(p[4].get<float>());
      cloud.ring.push_back(p[6].get<int16_t>());
      cloud.time_offset_s.push_back(static_cast<float>(p[0].get<uint32_t>() * 1e-9));  // timebase is the stamp
    }
    clouds.push_back(cloud);
  }
  return clouds;
}

using testing::ExpectSameCloud;

class LivoxReference : public ::testing::TestWithParam<std::string> {};

TEST_P(LivoxReference, CustomMsgAndPointCloud2ImportToTheSameScansSkippingTheGarbledOnes) {
  const Imported custom = Import(GetParam(), "/livox/lidar");
  const Imported cloud2 = Import(GetParam(), "/livox/points");
  EXPECT_EQ(custom.report.scans, 3);
  EXPECT_EQ(custom.report.images, 3);
  ASSERT_EQ(custom.report.warnings.size(), 1u);
  EXPECT_EQ(custom.report.warnings[0].rfind("/livox/lidar: 2 message(s) skipped, the first: livox_ros_driver2/", 0), 0u)
      << custom.report.warnings[0];
  EXPECT_NE(custom.report.warnings[0].find("field 'points' length 300 runs past the end"), std::string::npos)
      << custom.report.warnings[0];
  EXPECT_TRUE(cloud2.report.warnings.empty());
  const std::vector<PointCloud> expected = ExpectedClouds();
  ASSERT_EQ(custom.scans.size(), expected.size());
  ASSERT_EQ(cloud2.scans.size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    SCOPED_TRACE("scan " + std::to_string(k));
    EXPECT_EQ(custom.scans[k].utime, 1700000000123456 + static_cast<int64_t>(k) * 100000);
    EXPECT_EQ(cloud2.scans[k].utime, custom.scans[k].utime);
    EXPECT_EQ(custom.scans[k].cloud.size(), 300u - 6u);  // 3 without a return as NaN, 3 at the origin
    ExpectSameCloud(custom.scans[k].cloud, expected[k]);
    ExpectSameCloud(cloud2.scans[k].cloud, expected[k]);
  }
}

TEST(LivoxImport, ATopicOfAnotherTypeAsTheCloudNamesBothCloudTypes) {
  try {
    Import("livox.mcap", "/camera/image_raw");
    FAIL() << "imported an image topic as clouds";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("topic /camera/image_raw is sensor_msgs/msg/Image, the cloud must be "
                                         "sensor_msgs/msg/PointCloud2 or livox_ros_driver2/msg/CustomMsg"),
              std::string::npos)
        << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(WrittenByOthers, LivoxReference, ::testing::Values("livox.bag", "livox.mcap", "livox.db3"),
                         [](const auto& info) { return fs::path(info.param).extension().string().substr(1); });

}  // namespace
}  // namespace fusecal
