// `fusecal run --ros2` against a ROS 2 robot played by a peer on Fast DDS (ROS 2's default middleware,
// its own implementation) or on Cyclone with rosidl's types: a simulated recording (tiny-pinhole) published as
// sensor_msgs topics (or the clouds as Livox's CustomMsg) at recorded pace gives the extrinsic `fusecal calibrate`
// gives on the same log (same stations, so within 1e-6), and a reader of rt/tf_static that joins late gets it. Without
// the sensor topics the run ends with the list of what the domain has, exit 1.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <regex>
#include <thread>

#include "fusecal/station_t.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/formats/result_file.hpp"
#include "tests/support/process_utils.hpp"

namespace fusecal {
namespace {

namespace fs = std::filesystem;
using testing::ReadAll;
using testing::RunCommand;
using testing::StartInBackground;

const std::string kFusecal = FUSECAL_BIN;

std::string Dir() { return ::testing::TempDir() + "fusecal_ros2_live_" + std::to_string(getpid()); }

// The recording and what `calibrate` makes of it, once for the suite.
class Ros2Live : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    fs::create_directories(Dir());
    log_ = Dir() + "/tiny.lcmlog";
    ASSERT_EQ(RunCommand(kFusecal + " simulate --scenario " + SCENARIO_DIR "/tiny-pinhole.yaml --out " + log_ +
                         " > /dev/null 2>&1")
                  .exit_code,
              0);
    const auto calibrated = RunCommand(kFusecal + " calibrate --log " + log_ + " --out " + Dir() + "/ref 2>&1");
    ASSERT_EQ(calibrated.exit_code, 0) << calibrated.output;
    reference_ = ReadResultFile(Dir() + "/ref/extrinsic.yaml");
  }

  // The pipeline config as shipped, which names no ROS 2 domain: the run takes ROS_DOMAIN_ID (RunRos2).
  static std::string Config(int domain, double topic_timeout_s, const std::string& image_topic = "/camera/image_raw",
                            const std::string& cloud_type = "sensor_msgs/msg/PointCloud2") {
    std::string text = ReadAll(PIPELINE_CONFIG);
    EXPECT_FALSE(std::regex_search(text, std::regex("\\n  domain:"))) << "the shipped config sets a ROS 2 domain";
    text = std::regex_replace(text, std::regex("topic_timeout_s: 15"),
                              "topic_timeout_s: " + std::to_string(topic_timeout_s));
    text = std::regex_replace(text, std::regex("image_topic: /camera/image_raw"), "image_topic: " + image_topic);
    text = std::regex_replace(text, std::regex("cloud_type: sensor_msgs/msg/PointCloud2"), "cloud_type: " + cloud_type);
    const std::string path = Dir() + "/config_" + std::to_string(domain) + ".yaml";
    std::ofstream(path) << text;
    return path;
  }

  // `fusecal run --ros2` in ROS 2 domain `domain`, set as ROS 2 users set it.
  static std::string RunRos2(int domain) {
    return "env ROS_DOMAIN_ID=" + std::to_string(domain) + " " + kFusecal + " run --ros2";
  }

  // LCM on a port of its own, so that tests running at the same time do not meet.
  static std::string Bus(int domain) {
    return "'udpm://239.255.76.67:" + std::to_string(7700 + domain) + "?ttl=0&recv_buf_size=67108864'";
  }

  // Until `path` has not grown for `quiet_s` (the pipeline has settled), at most `max_s`.
  static void WaitQuiet(const std::string& path, double quiet_s, double max_s) {
    using Clock = std::chrono::steady_clock;
    const auto end = Clock::now() + std::chrono::duration<double>(max_s);
    auto last_change = Clock::now();
    uintmax_t last_size = 0;
    while (Clock::now() < end && Clock::now() - last_change < std::chrono::duration<double>(quiet_s)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      std::error_code error;
      const uintmax_t size = fs::file_size(path, error);
      if (!error && size != last_size) last_size = size, last_change = Clock::now();
    }
  }

  // Plays the recording through `peer` (its `play` and `tf-listen` commands) into `fusecal run --ros2`.
  // With `shared_memory`, no bus is named: the run chooses its own (iox://, RouDi started by the run).
  void CalibrateLive(const std::string& peer, int domain, const std::string& play_flags,
                     const std::string& image_topic = "/camera/image_raw",
                     const std::string& cloud_type = "sensor_msgs/msg/PointCloud2", bool shared_memory = false) {
    const std::string out = Dir() + "/live_" + std::to_string(domain), run_log = out + ".log";
    fs::remove_all(out);
    const pid_t run = StartInBackground(RunRos2(domain) + " --config " + Config(domain, 30, image_topic, cloud_type) +
                                            (shared_memory ? "" : " --bus " + Bus(domain)) + " --out " + out,
                                        run_log);
    ASSERT_GT(run, 0);
    const auto played =
        RunCommand(peer + " play " + log_ + " --domain " + std::to_string(domain) + " " + play_flags + " 2>&1");
    EXPECT_EQ(played.exit_code, 0) << played.output << ReadAll(run_log);
    WaitQuiet(run_log, 3, 30);
    const auto tf = RunCommand(peer + " tf-listen --domain " + std::to_string(domain) + " --timeout 10 2>&1");
    kill(run, SIGINT);
    int status = 0;
    waitpid(run, &status, 0);
    const std::string output = ReadAll(run_log);
    ASSERT_TRUE(WIFEXITED(status)) << output;
    EXPECT_EQ(WEXITSTATUS(status), 0) << output;  // converged and written
    EXPECT_NE(output.find("converged: written to " + out + "/extrinsic.yaml"), std::string::npos) << output;
#ifdef FUSECAL_WITH_IOX
    const std::string bus_said = shared_memory ? "the stages take the frames over shared memory (iox://"
                                               : "the stages take the frames over udpm://";
#else
    const std::string bus_said = "the stages take the frames over udpm://";  // no iceoryx in this build
#endif
    EXPECT_NE(output.find(bus_said), std::string::npos) << output;

    // The same stations (the frames each was taken from) give the same extrinsic. Under load a frame can
    // be missed (best effort) or skipped (a busy stage's queue), and another frame makes the station:
    // then the answer is close, not equal.
    const CalibrationResult live = ReadResultFile(out + "/extrinsic.yaml");
    const double difference = (live.T_camera_lidar.matrix() - reference_.T_camera_lidar.matrix()).cwiseAbs().maxCoeff();
    const auto stations = Stations(out + "/session.lcmlog"), expected = Stations(Dir() + "/ref/session.lcmlog");
    if (stations == expected) {
      EXPECT_LT(difference, 1e-6) << "live:\n"
                                  << live.T_camera_lidar.matrix() << "\ncalibrate:\n"
                                  << reference_.T_camera_lidar.matrix() << "\n"
                                  << output;
    } else {
      std::cout << "stations differ from calibrate's (frames missed under load): " << stations.size() << " vs "
                << expected.size() << "; largest difference in T " << difference << "\n";
      EXPECT_LT(difference, 0.05) << output;
    }

    // {"parent":"camera","child":"lidar","stamp":[..],"t":[x,y,z],"q":[x,y,z,w]}
    ASSERT_EQ(tf.exit_code, 0) << tf.output;
    std::smatch m;
    const std::string number = "(-?[0-9.eE+-]+)";
    ASSERT_TRUE(std::regex_search(tf.output, m,
                                  std::regex("\"t\":\\[" + number + "," + number + "," + number + "\\],\"q\":\\[" +
                                             number + "," + number + "," + number + "," + number + "\\]")))
        << tf.output;
    const Eigen::Vector3d t(std::stod(m[1]), std::stod(m[2]), std::stod(m[3]));
    const Eigen::Quaterniond q(std::stod(m[7]), std::stod(m[4]), std::stod(m[5]), std::stod(m[6]));
    EXPECT_NE(tf.output.find("\"parent\":\"camera\",\"child\":\"lidar\""), std::string::npos) << tf.output;
    EXPECT_LT((t - live.T_camera_lidar.translation()).norm(), 1e-12) << tf.output;
    EXPECT_LT((q.toRotationMatrix() - live.T_camera_lidar.linear()).cwiseAbs().maxCoeff(), 1e-12) << tf.output;
  }

  // (image stamp, scan stamp) of every station of a session log.
  static std::vector<std::pair<int64_t, int64_t>> Stations(const std::string& session_log) {
    std::vector<std::pair<int64_t, int64_t>> stations;
    LogReader reader(session_log);
    while (auto event = reader.Next()) {
      if (event->channel != "STATION") continue;
      station_t station{};
      if (station.decode(event->data.data(), 0, static_cast<int>(event->data.size())) >= 0)
        stations.emplace_back(station.image.utime, station.cloud.utime);
    }
    return stations;
  }

  static std::string log_;
  static CalibrationResult reference_;
};

std::string Ros2Live::log_;
CalibrationResult Ros2Live::reference_;

TEST_F(Ros2Live, CyclonePeerWithRosidlTypesBestEffortRawImages) { CalibrateLive(CYCLONE_PEER_BIN, 72, ""); }

TEST_F(Ros2Live, CyclonePeerReliableCompressedImages) {
  CalibrateLive(CYCLONE_PEER_BIN, 73, "--reliable --compressed", "/camera/image_raw/compressed");
}

// ROS 2's default middleware, reliable (its peer's default) with raw images.
TEST_F(Ros2Live, FastDdsPeerAsRos2sDefaultMiddleware) { CalibrateLive(FASTDDS_PEER_BIN, 74, ""); }

TEST_F(Ros2Live, FastDdsPeerBestEffortCompressedImages) {
  CalibrateLive(FASTDDS_PEER_BIN, 76, "--best-effort --compressed", "/camera/image_raw/compressed");
}

// A Livox LiDAR: the clouds as livox_ros_driver2/msg/CustomMsg (ros2_input.cloud_type).
TEST_F(Ros2Live, FastDdsPeerLivoxCustomMsg) {
  CalibrateLive(FASTDDS_PEER_BIN, 77, "--livox", "/camera/image_raw", "livox_ros_driver2/msg/CustomMsg");
}

// Every stage on this host and no bus named: the frames go to the stages over shared memory.
TEST_F(Ros2Live, FastDdsPeerIntoStagesOnSharedMemory) {
  CalibrateLive(FASTDDS_PEER_BIN, 78, "", "/camera/image_raw", "sensor_msgs/msg/PointCloud2", true);
}

// A rig of two cameras (tiny-pinhole's LiDAR and motions, a stereo pair) on two image topics.
const char* kTinyStereo = R"(seed: 7
scene: indoor
cameras:
  - {name: left, model: pinhole, width: 640, height: 480, fx: 320.0, fy: 320.0, cx: 319.5, cy: 239.5,
     dist: [-0.05, 0.01, 0.0, 0.0, 0.0], rate_hz: 10, phase_s: 0.013, supersample: 2, moving_supersample: 1,
     extrinsic: {xyz_m: [0.0895, 0.1218, -0.0458], rpy_deg: [-125.8556, -87.5002, -143.1182]}}
  - {name: right, model: pinhole, width: 640, height: 480, fx: 320.0, fy: 320.0, cx: 319.5, cy: 239.5,
     dist: [-0.05, 0.01, 0.0, 0.0, 0.0], rate_hz: 10, phase_s: 0.038, supersample: 2, moving_supersample: 1,
     extrinsic: {xyz_m: [-0.0305, 0.1218, -0.0458], rpy_deg: [-125.8556, -87.5002, -143.1182]}}
lidar: {model: multibeam, beams: 16, elevation_deg: [15.0, -15.0], azimuth_resolution_deg: 1.0, max_range_m: 100,
        rate_hz: 10, phase_s: 0.047}
motions: {horizontal: 3, vertical: 3, rotation_deg: [10, 20], tilt_deg: [8, 12], still_s: 2.0, move_s: [1.0, 1.5]}
noise: {image_sigma: 2.0, lidar_range_sigma_m: 0.01, lidar_dropout: 0.01}
)";

TEST_F(Ros2Live, FastDdsPeerWithTwoImageTopicsCalibratesBothCameras) {
  const std::string scenario = Dir() + "/tiny-stereo.yaml", log = Dir() + "/tiny-stereo.lcmlog";
  std::ofstream(scenario) << kTinyStereo;
  ASSERT_EQ(RunCommand(kFusecal + " simulate --scenario " + scenario + " --out " + log + " > /dev/null 2>&1").exit_code,
            0);
  const auto calibrated = RunCommand(kFusecal + " calibrate --log " + log + " --out " + Dir() + "/ref-stereo 2>&1");
  ASSERT_EQ(calibrated.exit_code, 0) << calibrated.output;

  const int domain = 79;
  std::string config = ReadAll(Config(domain, 30));
  config = "cameras: [{name: left}, {name: right}]\n" +
           std::regex_replace(config, std::regex("\n  depth: 4\n"),
                              "\n  depth: 4\n  cameras: [{name: left, image_topic: /left/image_raw}, "
                              "{name: right, image_topic: /right/image_raw}]\n");
  const std::string config_path = Dir() + "/config_stereo.yaml", out = Dir() + "/live_stereo", run_log = out + ".log";
  std::ofstream(config_path) << config;
  const pid_t run = StartInBackground(
      RunRos2(domain) + " --config " + config_path + " --bus " + Bus(domain) + " --out " + out, run_log);
  ASSERT_GT(run, 0);
  const auto played = RunCommand(std::string(FASTDDS_PEER_BIN) + " play " + log + " --domain " +
                                 std::to_string(domain) + " --rig-camera left --rig-camera right 2>&1");
  EXPECT_EQ(played.exit_code, 0) << played.output << ReadAll(run_log);
  EXPECT_NE(played.output.find("\"/right/image_raw\": "), std::string::npos) << played.output;
  WaitQuiet(run_log, 3, 30);
  kill(run, SIGINT);
  int status = 0;
  waitpid(run, &status, 0);
  const std::string output = ReadAll(run_log);
  ASSERT_TRUE(WIFEXITED(status)) << output;
  EXPECT_EQ(WEXITSTATUS(status), 0) << output;  // every camera converged and written
  EXPECT_NE(output.find("camera left /left/image_raw, /left/camera_info, camera right /right/image_raw"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("every camera converged: written to " + out + "/extrinsic.yaml"), std::string::npos) << output;
  // Both cameras, against calibrate's answer on the same log (the same stations, unless a frame was missed
  // under load: then close).
  const auto eval = RunCommand(kFusecal + " evaluate --result " + out + "/extrinsic.yaml --truth " + Dir() +
                               "/ref-stereo/extrinsic.yaml 2>&1");
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  EXPECT_NE(eval.output.find("\"left\":{\"rot_err_deg\""), std::string::npos) << eval.output;
  EXPECT_NE(eval.output.find("\"right\":{\"rot_err_deg\""), std::string::npos) << eval.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(eval.output, m,
                                std::regex("\"max_rot_err_deg\":([-0-9.eE+]+),\"max_trans_err_m\":([-0-9.eE+]+)")))
      << eval.output;
  EXPECT_LT(std::stod(m[1]), 0.05) << eval.output;
  EXPECT_LT(std::stod(m[2]), 0.005) << eval.output;
}

TEST_F(Ros2Live, NoPublisherEndsWithWhatTheDomainHas) {
  const std::string out = Dir() + "/silent";
  const auto run =
      RunCommand(RunRos2(75) + " --config " + Config(75, 3) + " --bus " + Bus(75) + " --out " + out + " 2>&1");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("no message in 3 s on ROS 2 domain 75 on /camera/image_raw (sensor_msgs/msg/Image), "
                            "/lidar/points (sensor_msgs/msg/PointCloud2), /camera/camera_info"),
            std::string::npos)
      << run.output;
  // The only writers on the domain are the run's own (fusecal-ros2-tf).
  EXPECT_NE(run.output.find("the domain has: /diagnostics (diagnostic_msgs/msg/DiagnosticArray), /fusecal/overlay "
                            "(sensor_msgs/msg/Image), /tf_static (tf2_msgs/msg/TFMessage). Set ros2_input.image_topic"),
            std::string::npos)
      << run.output;
}

}  // namespace
}  // namespace fusecal
