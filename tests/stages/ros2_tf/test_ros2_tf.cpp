// fusecal-ros2-tf as a ROS 2 system would see it: a Cyclone DDS reader of tf2_msgs::msg::dds_::TFMessage_
// on rt/tf_static (reliable, transient local, joining late) receives the extrinsic published on the
// fusecal bus, with the config's frame ids.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <chrono>
#include <fstream>
#include <map>
#include <string>
#include <thread>

#include "dds/dds.h"
#include "fusecal/extrinsic_t.hpp"
#include "fusecal/station_t.hpp"
#include "ros2_messages.h"
#include "runtime/bus.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/ros2_tf/node/ros2_views.hpp"

namespace fusecal {
namespace {

const std::string kBus = "udpm://239.255.76.67:7686?ttl=0&recv_buf_size=67108864";
constexpr int kDomain = 38;

pid_t Start(const std::string& config, const std::string& log) {
  const pid_t pid = fork();
  if (pid == 0) {
    const std::string command =
        std::string(ROS2_TF_BIN) + " --config " + config + " --bus '" + kBus + "' > " + log + " 2>&1";
    execl("/bin/sh", "sh", "-c", ("exec " + command).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

TEST(Ros2Tf, AStaticTransformReachesARos2ReaderWithTheConfiguredFrames) {
  const std::string dir = ::testing::TempDir() + "fusecal_ros2_tf_" + std::to_string(getpid());
  const std::string config = dir + ".yaml", log = dir + ".log";
  std::ofstream(config) << "ros2_tf:\n  domain: " << kDomain
                        << "\n  parent_frame: cam_front\n  child_frame: velo_top\n";
  const pid_t pid = Start(config, log);
  ASSERT_GT(pid, 0);

  // The extrinsic: a rotation of 30 deg about (1, 2, 3) and t = (0.1, -0.2, 0.3).
  Isometry3 X = Isometry3::Identity();
  X.linear() = Eigen::AngleAxisd(30 * M_PI / 180, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.1, -0.2, 0.3);
  extrinsic_t e{};
  e.utime = 1700000001500000;
  e.version = 7;
  ToRowMajor(X, e.T_camera_lidar);
  e.status = extrinsic_t::STATUS_CONVERGED;
  e.converged = true;
  auto bus = MakeBus(kBus);
  // Published until the stage is surely up (it ignores repeats of a version).
  for (int k = 0; k < 30; ++k) {
    bus->Publish("EXTRINSIC", e);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  // A failed version (no estimate; the identity, as after a change of the rig) does not replace it.
  extrinsic_t failed = e;
  failed.version = 8;
  ToRowMajor(Isometry3::Identity(), failed.T_camera_lidar);
  failed.status = extrinsic_t::STATUS_FAILED;
  failed.converged = false;
  for (int k = 0; k < 5; ++k) {
    bus->Publish("EXTRINSIC", failed);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }

  // A late reader: transient local hands it the last sample.
  const dds_entity_t participant = dds_create_participant(kDomain, nullptr, nullptr);
  ASSERT_GT(participant, 0);
  const dds_entity_t topic =
      dds_create_topic(participant, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf_static", nullptr, nullptr);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  const dds_entity_t reader = dds_create_reader(participant, topic, qos, nullptr);
  dds_delete_qos(qos);
  ASSERT_GT(reader, 0);
  void* samples[1] = {nullptr};
  dds_sample_info_t info[1];
  int taken = 0;
  for (int k = 0; k < 100 && taken <= 0; ++k) {
    taken = dds_take(reader, samples, info, 1, 1);
    if (taken <= 0 || !info[0].valid_data) {
      if (taken > 0) dds_return_loan(reader, samples, taken);
      taken = 0;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  kill(pid, SIGTERM);
  waitpid(pid, nullptr, 0);
  std::ifstream in(log);
  const std::string output((std::istreambuf_iterator<char>(in)), {});
  ASSERT_EQ(taken, 1) << "no TFMessage on rt/tf_static in domain " << kDomain << "\n" << output;
  const auto* message = static_cast<const tf2_msgs_msg_dds__TFMessage_*>(samples[0]);
  ASSERT_EQ(message->transforms_._length, 1u);
  const auto& t = message->transforms_._buffer[0];
  EXPECT_STREQ(t.header_.frame_id_, "cam_front");
  EXPECT_STREQ(t.child_frame_id_, "velo_top");
  EXPECT_EQ(t.header_.stamp_.sec_, 1700000001);
  EXPECT_EQ(t.header_.stamp_.nanosec_, 500000000u);
  EXPECT_NEAR(t.transform_.translation_.x_, 0.1, 1e-12);
  EXPECT_NEAR(t.transform_.translation_.y_, -0.2, 1e-12);
  EXPECT_NEAR(t.transform_.translation_.z_, 0.3, 1e-12);
  const Eigen::Quaterniond q(t.transform_.rotation_.w_, t.transform_.rotation_.x_, t.transform_.rotation_.y_,
                             t.transform_.rotation_.z_);
  EXPECT_LT(RotationErrorDeg(q.toRotationMatrix(), X.linear()), 1e-9);
  dds_return_loan(reader, samples, taken);
  dds_delete(participant);
}

// The overlay and diagnostics a ROS 2 user looks at: after a STATION and an EXTRINSIC on the bus, a late
// reader of the overlay topic gets the station's image with the points drawn, and a reader of
// rt/diagnostics the verdict and the estimate.
TEST(Ros2Tf, TheOverlayImageAndTheDiagnosticsReachRos2Readers) {
  constexpr int kViewsDomain = 39;
  const std::string dir = ::testing::TempDir() + "fusecal_ros2_views_" + std::to_string(getpid());
  const std::string config = dir + ".yaml", log = dir + ".log";
  std::ofstream(config) << "ros2_tf:\n  domain: " << kViewsDomain << "\n  overlay_topic: /calib/overlay\n";
  const dds_entity_t participant = dds_create_participant(kViewsDomain, nullptr, nullptr);
  ASSERT_GT(participant, 0);
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  const dds_entity_t diagnostics =
      dds_create_reader(participant,
                        dds_create_topic(participant, &diagnostic_msgs_msg_dds__DiagnosticArray__desc, "rt/diagnostics",
                                         nullptr, nullptr),
                        qos, nullptr);
  dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  const dds_entity_t overlay = dds_create_reader(
      participant,
      dds_create_topic(participant, &sensor_msgs_msg_dds__Image__desc, "rt/calib/overlay", nullptr, nullptr), qos,
      nullptr);
  dds_delete_qos(qos);
  const pid_t pid = Start(config, log);
  ASSERT_GT(pid, 0);

  // A grey 64x48 image, points 4 m ahead on a 5x5 grid, a pinhole camera; X = identity.
  station_t station{};
  station.utime = 1700000002000000;
  station.id = 3;
  // The frames as a ROS 2 robot's headers name them (the config names none).
  station.image = MatToImage(cv::Mat(48, 64, CV_8UC1, cv::Scalar(128)), "mono8", station.utime, "cam0_optical");
  PointCloud cloud;
  for (int i = -2; i <= 2; ++i)
    for (int j = -2; j <= 2; ++j) cloud.points.emplace_back(0.5f * i, 0.4f * j, 4.0f);
  station.cloud = CloudToMsg(cloud, station.utime, "os_sensor");
  CameraParams camera;
  camera.width = 64;
  camera.height = 48;
  camera.fx = camera.fy = 40;
  camera.cx = 31.5;
  camera.cy = 23.5;
  station.camera = CameraToMsg(camera);
  extrinsic_t e{};
  e.utime = station.utime + 1000;
  e.version = 4;
  ToRowMajor(Isometry3::Identity(), e.T_camera_lidar);
  e.status = extrinsic_t::STATUS_CONVERGED;
  e.converged = true;
  auto bus = MakeBus(kBus);
  void* image_sample[1] = {nullptr};
  void* diagnostic_sample[1] = {nullptr};
  dds_sample_info_t info[1];
  int images = 0, arrays = 0;
  for (int k = 0; k < 100 && (images <= 0 || arrays <= 0); ++k) {
    bus->Publish("STATION", station);
    bus->Publish("EXTRINSIC", e);
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (images <= 0) images = dds_take(overlay, image_sample, info, 1, 1);
    if (arrays <= 0) arrays = dds_take(diagnostics, diagnostic_sample, info, 1, 1);
  }
  kill(pid, SIGTERM);
  waitpid(pid, nullptr, 0);
  std::ifstream in(log);
  const std::string output((std::istreambuf_iterator<char>(in)), {});
  ASSERT_EQ(images, 1) << output;
  ASSERT_EQ(arrays, 1) << output;
  const auto* image = static_cast<const sensor_msgs_msg_dds__Image_*>(image_sample[0]);
  EXPECT_EQ(image->width_, 64u);
  EXPECT_EQ(image->height_, 48u);
  EXPECT_STREQ(image->encoding_, "bgr8");
  EXPECT_STREQ(image->header_.frame_id_, "cam0_optical");
  ASSERT_EQ(image->data_._length, 64u * 48u * 3u);
  int coloured = 0;  // pixels no longer grey: the drawn points
  for (uint32_t p = 0; p < 64 * 48; ++p) {
    const uint8_t* bgr = &image->data_._buffer[3 * p];
    coloured += bgr[0] != bgr[1] || bgr[1] != bgr[2];
  }
  EXPECT_GE(coloured, 25) << "the 25 points are not drawn";
  const auto* array = static_cast<const diagnostic_msgs_msg_dds__DiagnosticArray_*>(diagnostic_sample[0]);
  ASSERT_EQ(array->status_._length, 1u);
  const auto& status = array->status_._buffer[0];
  EXPECT_EQ(status.level_, 0);  // OK: converged
  EXPECT_STREQ(status.message_, "converged (ok)");
  std::map<std::string, std::string> values;
  for (uint32_t i = 0; i < status.values_._length; ++i)
    values[status.values_._buffer[i].key_] = status.values_._buffer[i].value_;
  EXPECT_EQ(values["version"], "4");
  EXPECT_STREQ(status.hardware_id_, "cam0_optical");
  EXPECT_EQ(values["translation_m"], "[0.0000, 0.0000, 0.0000]");
  dds_return_loan(overlay, image_sample, 1);
  dds_return_loan(diagnostics, diagnostic_sample, 1);
  dds_delete(participant);
}

// After a change of the rig the diagnostics warn until the loop has converged again, and say after which
// station the extrinsic changed and what it was before.
TEST(Ros2TfDiagnostics, AChangedRigWarnsUntilConvergedAndSaysWhatChanged) {
  extrinsic_t e{};
  e.version = 9;
  ToRowMajor(Isometry3::Identity(), e.T_camera_lidar);
  e.status = extrinsic_t::STATUS_REFINING;
  Isometry3 before = Isometry3::Identity();
  before.translation() = Eigen::Vector3d(0.1, 0, 0);
  std::vector<double> T(16), C(36, 0.0);
  ToRowMajor(before, T.data());
  e.num_changes = 1;
  e.change_after_station = {3};
  e.change_decided_at_station = {5};
  e.change_T_before = {T};
  e.change_covariance_before = {C};
  DiagnosticReport report = DescribeExtrinsic(e);
  EXPECT_EQ(report.level, 1);
  EXPECT_NE(report.message.find("extrinsic changed after station 3"), std::string::npos) << report.message;
  std::map<std::string, std::string> values(report.values.begin(), report.values.end());
  EXPECT_EQ(values["changed_after_station"], "3");
  EXPECT_EQ(values["before_translation_m"], "[0.1000, 0.0000, 0.0000]");
  e.status = extrinsic_t::STATUS_CONVERGED;
  EXPECT_EQ(DescribeExtrinsic(e).level, 0);
  // A failed version right after a change: the values are those of the version tf_static still holds.
  extrinsic_t failed = e;
  failed.version = 10;
  failed.status = extrinsic_t::STATUS_FAILED;
  ToRowMajor(Isometry3::Identity(), failed.T_camera_lidar);
  extrinsic_t held = e;
  held.T_camera_lidar[3] = 0.25;
  report = DescribeExtrinsic(failed, &held);
  EXPECT_EQ(report.level, 1);
  EXPECT_NE(report.message.find("tf_static holds version 9"), std::string::npos) << report.message;
  values = std::map<std::string, std::string>(report.values.begin(), report.values.end());
  EXPECT_EQ(values["translation_m"], "[0.2500, 0.0000, 0.0000]");
  EXPECT_EQ(values["status"], "failed");
  EXPECT_EQ(values["tf_static_version"], "9");
  EXPECT_EQ(DescribeExtrinsic(failed).level, 2) << "nothing held";
}

// A robot whose tree already gives the LiDAR frame a parent gets the calibration under another child
// name, so that no frame has two parents (tf2 rejects that); a frame without one keeps its name.
TEST(Ros2TfTree, AFrameWithAParentAlreadyGetsTheCalibrationUnderANewName) {
  FrameParents frames;
  EXPECT_EQ(frames.ChildName("camera", "lidar_link"), "lidar_link");
  frames.Add("/base_link", "lidar_link");
  frames.Add("camera", "velodyne");  // the calibration's own parent is no second parent
  EXPECT_EQ(frames.ChildName("camera", "lidar_link"), "lidar_link_calibrated");
  EXPECT_EQ(frames.OtherParent("camera", "lidar_link"), "base_link");
  EXPECT_EQ(frames.ChildName("camera", "velodyne"), "velodyne");
  EXPECT_EQ(frames.ChildName("camera", "/lidar_link"), "/lidar_link_calibrated");
}

}  // namespace
}  // namespace fusecal
