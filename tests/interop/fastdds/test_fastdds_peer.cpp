// fastdds_ros2_peer, the Fast DDS side of the ROS 2 interoperability tests: a simulated recording played
// through Fast DDS is counted back by Fast DDS readers message for message, and fusecal-ros2-tf's
// rt/tf_static (Cyclone DDS) reaches a late-joining Fast DDS reader with the extrinsic's values.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <algorithm>

#include <Eigen/Geometry>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <thread>

#include "fusecal/extrinsic_t.hpp"
#include "runtime/bus.hpp"
#include "stages/formats/conversions.hpp"
#include "tests/support/process_utils.hpp"

namespace fusecal {
namespace {

namespace fs = std::filesystem;
using testing::ReadAll;
using testing::RunCommand;
using testing::StartInBackground;

const std::string kPeer = FASTDDS_PEER_BIN;
const std::string kFusecal = FUSECAL_BIN;

std::string Dir() { return ::testing::TempDir() + "fusecal_fastdds_peer_" + std::to_string(getpid()); }

// `fusecal log info`'s message count per channel ("  CAMERA_IMAGE  count=151  type=...").
std::map<std::string, long> ChannelCounts(const std::string& log) {
  const auto info = RunCommand(kFusecal + " log info " + log + " 2>&1");
  std::map<std::string, long> counts;
  const std::regex line("\\n\\s*([A-Z_]+)\\s+count=([0-9]+)");
  for (std::sregex_iterator it(info.output.begin(), info.output.end(), line), end; it != end; ++it)
    counts[(*it)[1]] = std::stol((*it)[2]);
  return counts;
}

class FastDdsPeer : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { fs::create_directories(Dir()); }
  static void TearDownTestSuite() { fs::remove_all(Dir()); }

  // A recording with camera and LiDAR streams (tiny-pinhole, 15 s), made once for the suite.
  static void Simulate() {
    if (!log_.empty()) return;
    const std::string log = Dir() + "/tiny.lcmlog";
    const auto simulated =
        RunCommand(kFusecal + " simulate --scenario " SCENARIO_DIR "/tiny-pinhole.yaml --out " + log + " 2>&1");
    ASSERT_EQ(simulated.exit_code, 0) << simulated.output;
    log_ = log;
    counts_ = ChannelCounts(log_);
  }

  // Plays the recording into a counting peer on `domain`; returns what the counter printed.
  static nlohmann::json PlayAndCount(int domain, const std::string& play_flags, const std::string& count_flags) {
    const std::string counted = Dir() + "/count_" + std::to_string(domain) + ".json";
    const pid_t counter = StartInBackground(
        kPeer + " count --domain " + std::to_string(domain) + " --seconds 40 --idle 3 " + count_flags, counted);
    EXPECT_GT(counter, 0);
    const auto played = RunCommand(kPeer + " play " + log_ + " --domain " + std::to_string(domain) + " --speed 5 " +
                                   play_flags + " 2>&1");
    if (played.exit_code != 0) kill(counter, SIGTERM);  // nothing to wait for
    int status = 0;
    waitpid(counter, &status, 0);
    const std::string output = ReadAll(counted);
    EXPECT_EQ(played.exit_code, 0) << played.output << "\ncount: " << output;
    EXPECT_TRUE(played.exit_code != 0 || (WIFEXITED(status) && WEXITSTATUS(status) == 0)) << output;
    const size_t brace = output.rfind("{\"received\"");
    if (brace == std::string::npos) {
      ADD_FAILURE() << "no count in: " << output << "\nplay: " << played.output;
      return {};
    }
    return nlohmann::json::parse(output.substr(brace));
  }

  static std::string log_;
  static std::map<std::string, long> counts_;
};

std::string FastDdsPeer::log_;
std::map<std::string, long> FastDdsPeer::counts_;

TEST_F(FastDdsPeer, PlaysALogAndCountsItBack) {
  ASSERT_NO_FATAL_FAILURE(Simulate());
  ASSERT_GT(counts_["CAMERA_IMAGE"], 0);
  ASSERT_GT(counts_["LIDAR_SCAN"], 0);
  ASSERT_GT(counts_["CAMERA_INFO"], 0);
  const nlohmann::json received = PlayAndCount(61, "", "");
  ASSERT_TRUE(received.contains("received")) << received;
  const auto& topics = received["received"];
  EXPECT_EQ(topics["/camera/image_raw"]["messages"], counts_["CAMERA_IMAGE"]) << received;
  EXPECT_EQ(topics["/lidar/points"]["messages"], counts_["LIDAR_SCAN"]) << received;
  // The camera model beside every image, as camera drivers publish it.
  EXPECT_EQ(topics["/camera/camera_info"]["messages"], counts_["CAMERA_IMAGE"]) << received;
  // mono8 (the scenario's camera is grey), 640x480: every image carries its 307200 pixel bytes.
  EXPECT_GT(topics["/camera/image_raw"]["bytes"].get<long>(), counts_["CAMERA_IMAGE"] * 307200) << received;
}

TEST_F(FastDdsPeer, PlaysCompressedImagesWithTheSensorDataQos) {
  ASSERT_NO_FATAL_FAILURE(Simulate());
  const nlohmann::json received = PlayAndCount(
      62, "--compressed --best-effort", "--best-effort /camera/camera_info /camera/image_raw/compressed /lidar/points");
  ASSERT_TRUE(received.contains("received")) << received;
  // Best effort may drop a sample when the machine is busy (the suite runs tests side by side); the reliable
  // test above counts exactly. Here the types and the sensor-data QoS must match: nearly all arrive.
  const auto delivered = [&](const char* topic, long sent) {
    const long got = received["received"].value(topic, nlohmann::json::object()).value("messages", 0L);
    EXPECT_LE(got, sent) << topic << ": " << received;
    EXPECT_GE(got, sent - std::max(1L, sent / 50)) << topic << ": " << received;
  };
  delivered("/camera/image_raw/compressed", counts_["CAMERA_IMAGE"]);
  delivered("/lidar/points", counts_["LIDAR_SCAN"]);
}

#ifdef ROS2_TF_BIN
// Version 3 of `X`, converged, stamped 1700000001.5 s, on `bus` for 3 s: until fusecal-ros2-tf is surely up
// (it ignores repeats of a version).
void PublishConvergedExtrinsic(const std::string& bus, const Isometry3& X) {
  extrinsic_t e{};
  e.utime = 1700000001500000;
  e.version = 3;
  ToRowMajor(X, e.T_camera_lidar);
  e.status = extrinsic_t::STATUS_CONVERGED;
  e.converged = true;
  auto fusecal_bus = MakeBus(bus);
  for (int k = 0; k < 30; ++k) {
    fusecal_bus->Publish("EXTRINSIC", e);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

// fusecal-ros2-tf is fed one extrinsic on its LCM bus (a port of this test's own) and publishes it.
TEST_F(FastDdsPeer, ReadsTfStaticFromFusecal) {
  constexpr int kDomain = 63;
  const std::string config = Dir() + "/ros2_tf.yaml", node_log = Dir() + "/ros2_tf.log";
  const std::string bus = "udpm://239.255.76.67:" + std::to_string(7700 + kDomain) + "?ttl=0&recv_buf_size=67108864";
  std::ofstream(config) << "ros2_tf:\n  domain: " << kDomain << "\n";
  const pid_t node =
      StartInBackground(std::string(ROS2_TF_BIN) + " --config " + config + " --bus '" + bus + "'", node_log);
  ASSERT_GT(node, 0);

  // A rotation of 30 deg about (1, 2, 3) and t = (0.1, -0.2, 0.3).
  Isometry3 X = Isometry3::Identity();
  X.linear() = Eigen::AngleAxisd(30 * M_PI / 180, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.1, -0.2, 0.3);
  PublishConvergedExtrinsic(bus, X);  // the reader joins after the write
  const auto tf = RunCommand(kPeer + " tf-listen --domain " + std::to_string(kDomain) + " --timeout 15 2>&1");
  kill(node, SIGTERM);
  waitpid(node, nullptr, 0);
  ASSERT_EQ(tf.exit_code, 0) << tf.output << "\nfusecal-ros2-tf: " << ReadAll(node_log);
  const nlohmann::json t = nlohmann::json::parse(tf.output.substr(tf.output.find('{')));
  EXPECT_EQ(t["parent"], "camera") << tf.output;
  EXPECT_EQ(t["child"], "lidar") << tf.output;
  EXPECT_EQ(t["stamp"], nlohmann::json::array({1700000001, 500000000})) << tf.output;
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(t["t"][i].get<double>(), X.translation()[i], 1e-12) << tf.output;
  const Eigen::Quaterniond q(t["q"][3].get<double>(), t["q"][0].get<double>(), t["q"][1].get<double>(),
                             t["q"][2].get<double>());
  EXPECT_NEAR(q.norm(), 1.0, 1e-12) << tf.output;
  EXPECT_LT((q.toRotationMatrix() - X.linear()).cwiseAbs().maxCoeff(), 1e-12) << tf.output;
}

// A robot (Fast DDS, tf2_ros's static broadcaster QoS) whose tree has base_link -> lidar_link: the
// calibration arrives as camera -> lidar_link_calibrated, and lidar_link keeps its one parent.
TEST_F(FastDdsPeer, TheCalibrationGivesNoFrameASecondParent) {
  constexpr int kDomain = 64;
  const std::string config = Dir() + "/ros2_tf_tree.yaml", node_log = Dir() + "/ros2_tf_tree.log";
  const std::string bus = "udpm://239.255.76.67:" + std::to_string(7700 + kDomain) + "?ttl=0&recv_buf_size=67108864";
  std::ofstream(config) << "ros2_tf:\n  domain: " << kDomain << "\n  child_frame: lidar_link\n";
  const pid_t robot = StartInBackground(
      kPeer + " tf-static base_link lidar_link --seconds 40 --domain " + std::to_string(kDomain), Dir() + "/robot.log");
  ASSERT_GT(robot, 0);
  const pid_t node =
      StartInBackground(std::string(ROS2_TF_BIN) + " --config " + config + " --bus '" + bus + "'", node_log);
  ASSERT_GT(node, 0);
  std::this_thread::sleep_for(std::chrono::seconds(3));  // discovery: the node learns the robot's tree
  PublishConvergedExtrinsic(bus, Isometry3::Identity());
  const auto tf =
      RunCommand(kPeer + " tf-listen --count 2 --domain " + std::to_string(kDomain) + " --timeout 15 2>/dev/null");
  kill(node, SIGTERM);
  waitpid(node, nullptr, 0);
  kill(robot, SIGTERM);
  waitpid(robot, nullptr, 0);
  const std::string log = ReadAll(node_log);
  ASSERT_EQ(tf.exit_code, 0) << tf.output << "\nfusecal-ros2-tf: " << log;
  std::map<std::string, std::string> parent_of;
  std::istringstream lines(tf.output);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] != '{') continue;
    const nlohmann::json t = nlohmann::json::parse(line);
    EXPECT_EQ(parent_of.count(t["child"]), 0u) << "a second parent of " << t["child"] << ": " << tf.output;
    parent_of[t["child"]] = t["parent"];
  }
  EXPECT_EQ(parent_of["lidar_link"], "base_link") << tf.output;
  EXPECT_EQ(parent_of["lidar_link_calibrated"], "camera") << tf.output;
  EXPECT_NE(log.find("publishing the calibration as camera -> lidar_link_calibrated"), std::string::npos) << log;
}
#endif

}  // namespace
}  // namespace fusecal
