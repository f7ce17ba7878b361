// The ROS 2 input without DDS: CDR samples of each topic into frames (the conversions of `fusecal import
// rosbag`), malformed ones counted with their reason, losses judged from stamp gaps; the settings'
// checks and topic names; fusecal's types as ROS messages and back; Livox's CustomMsg as the cloud.
#include <gtest/gtest.h>

#include "stages/formats/ros2_names.hpp"
#include "stages/formats/ros_sensor_encode.hpp"
#include "stages/ros2_input/node/ros2_input_settings.hpp"
#include "stages/ros2_input/node/ros2_sensor_input.hpp"
#include "tests/support/cdr_writer.hpp"

namespace fusecal {
namespace {

using testing::CdrByteOrder;
using testing::EncodeCdr;

const int64_t kT0 = 1700000000000000;

CameraParams Pinhole() {
  CameraParams camera;
  camera.width = 8;
  camera.height = 6;
  camera.fx = camera.fy = 10;
  camera.cx = 3.5;
  camera.cy = 2.5;
  camera.dist = {-0.1, 0.01, 0, 0, 0};
  return camera;
}

RosHeader Header(int64_t utime) { return RosHeader{UtimeToRosStamp(utime), "sensor"}; }

TEST(StampGapCounter, CountsMissingPeriodsAndNotJitter) {
  StampGapCounter gaps;
  int64_t t = kT0;
  for (int i = 0; i < 10; ++i) EXPECT_EQ(gaps.Add(t += 100000 + (i % 2 ? 8000 : -8000)), 0) << i;
  EXPECT_EQ(gaps.Add(t += 300000), 2);  // two frames missing
  EXPECT_EQ(gaps.Add(t += 100000), 0);
  EXPECT_EQ(gaps.Add(t), 0);          // a repeated stamp is not a loss
  EXPECT_EQ(gaps.Add(t - 50000), 0);  // nor one out of order
  EXPECT_EQ(gaps.Add(t += 1000000), 9);
  EXPECT_EQ(gaps.lost(), 11);
}

TEST(Ros2SensorInput, EachTopicBecomesItsFrameAndTheCameraIsTakenOnce) {
  Ros2SensorInput input;
  const auto info = EncodeCdr(ToRosCameraInfo(Pinhole(), Header(kT0)), CdrByteOrder::kBig);
  const Ros2InputFrame first = input.Take(Ros2SensorTopic::kCameraInfo, info.data(), info.size(), kT0);
  ASSERT_TRUE(first.camera);
  EXPECT_EQ(first.camera->dist, Pinhole().dist);
  EXPECT_EQ(first.camera->fx, 10);
  EXPECT_FALSE(input.Take(Ros2SensorTopic::kCameraInfo, info.data(), info.size(), kT0).camera);  // unchanged

  cv::Mat pixels(6, 8, CV_8UC3, cv::Scalar(10, 20, 30));
  pixels.at<cv::Vec3b>(2, 3) = {1, 2, 3};
  const auto image = EncodeCdr(ToRosImage(pixels, RosHeader{UtimeToRosStamp(kT0 + 5), "cam0_optical"}));
  const Ros2InputFrame got = input.Take(Ros2SensorTopic::kImage, image.data(), image.size(), kT0 + 900);
  ASSERT_TRUE(got.image) << got.error;
  EXPECT_EQ(got.image->utime, kT0 + 5);            // the header stamp, not the arrival
  EXPECT_EQ(got.image->frame_id, "cam0_optical");  // the header's frame, for tf
  EXPECT_EQ(cv::norm(got.image->pixels, pixels, cv::NORM_INF), 0.0);

  PointCloud cloud;
  cloud.points = {{1, 2, 3}, {0, 0, 0}, {4, 5, 6}};
  cloud.intensity = {0.5f, 0.f, 7.f};
  cloud.ring = {0, 1, 63};
  const auto scan = EncodeCdr(ToRosPointCloud2(cloud, RosHeader{UtimeToRosStamp(kT0 + 7), "os_sensor"}));
  const Ros2InputFrame taken = input.Take(Ros2SensorTopic::kCloud, scan.data(), scan.size(), kT0 + 900);
  ASSERT_TRUE(taken.scan) << taken.error;
  EXPECT_EQ(taken.scan->frame_id, "os_sensor");
  EXPECT_EQ(taken.scan->dropped, 1);  // the point at the origin has no return
  ASSERT_EQ(taken.scan->cloud.size(), 2u);
  EXPECT_EQ(taken.scan->cloud.points[1], cloud.points[2]);
  EXPECT_EQ(taken.scan->cloud.intensity[1], 7.f);
  EXPECT_EQ(taken.scan->cloud.ring[1], 63);
  EXPECT_EQ(input.counts(Ros2SensorTopic::kCloud).used, 1);
  EXPECT_EQ(input.counts(Ros2SensorTopic::kCameraInfo).received, 2);
}

TEST(Ros2SensorInput, ALivoxCustomMsgBecomesAScanWithReflectivityLinesAndTimes) {
  Ros2SensorInput input(Pinhole());
  PointCloud cloud;
  cloud.points = {{1, 2, 3}, {0, 0, 0}, {4, 5, 6}};
  cloud.intensity = {12.4f, 0.f, 300.f};  // reflectivity is a byte: rounded and clamped
  cloud.ring = {0, 1, 3};
  cloud.time_offset_s = {-0.002f, 0.f, 0.0495f};
  const RosLivoxCustomMsg msg = ToRosLivoxCustomMsg(cloud, RosHeader{UtimeToRosStamp(kT0 + 7), "livox_frame"});
  EXPECT_EQ(msg.timebase, static_cast<uint64_t>(kT0 + 7) * 1000 - 2000000);  // the first point's time
  const auto bytes = EncodeCdr(msg, CdrByteOrder::kBig);
  const Ros2InputFrame taken = input.Take(Ros2SensorTopic::kLivoxCloud, bytes.data(), bytes.size(), kT0 + 900);
  ASSERT_TRUE(taken.scan) << taken.error;
  EXPECT_EQ(taken.scan->utime, kT0 + 7);
  EXPECT_EQ(taken.scan->frame_id, "livox_frame");
  EXPECT_EQ(taken.scan->dropped, 1);
  EXPECT_EQ(taken.scan->cloud.points, (std::vector<Eigen::Vector3f>{cloud.points[0], cloud.points[2]}));
  EXPECT_EQ(taken.scan->cloud.intensity, (std::vector<float>{12.f, 255.f}));
  EXPECT_EQ(taken.scan->cloud.ring, (std::vector<int16_t>{0, 3}));
  ASSERT_EQ(taken.scan->cloud.time_offset_s.size(), 2u);
  EXPECT_NEAR(taken.scan->cloud.time_offset_s[0], -0.002, 1e-8);
  EXPECT_NEAR(taken.scan->cloud.time_offset_s[1], 0.0495, 1e-8);
  const Ros2InputFrame garbled = input.Take(Ros2SensorTopic::kLivoxCloud, bytes.data(), bytes.size() - 3, kT0);
  EXPECT_NE(garbled.error.find("livox_ros_driver2/msg/CustomMsg"), std::string::npos) << garbled.error;
  EXPECT_EQ(input.counts(Ros2SensorTopic::kLivoxCloud).used, 1);
  EXPECT_EQ(input.counts(Ros2SensorTopic::kLivoxCloud).malformed, 1);
}

TEST(Ros2SensorInput, MalformedMessagesAreCountedWithTheFirstReason) {
  Ros2SensorInput input(Pinhole());  // from a camera file: CameraInfo is not used
  const auto info = EncodeCdr(ToRosCameraInfo(Pinhole(), Header(kT0)));
  EXPECT_FALSE(input.Take(Ros2SensorTopic::kCameraInfo, info.data(), info.size(), kT0).camera);

  auto image = EncodeCdr(ToRosImage(cv::Mat(6, 8, CV_8UC1, cv::Scalar(9)), Header(kT0)));
  image.resize(image.size() - 10);  // cut short
  const Ros2InputFrame cut = input.Take(Ros2SensorTopic::kImage, image.data(), image.size(), kT0);
  EXPECT_FALSE(cut.image);
  EXPECT_NE(cut.error.find("sensor_msgs/msg/Image"), std::string::npos) << cut.error;
  const auto wrong_size = EncodeCdr(ToRosImage(cv::Mat(4, 4, CV_8UC1, cv::Scalar(9)), Header(kT0)));
  EXPECT_FALSE(input.Take(Ros2SensorTopic::kImage, wrong_size.data(), wrong_size.size(), kT0).image);
  const uint8_t noise[3] = {0, 1, 2};
  EXPECT_FALSE(input.Take(Ros2SensorTopic::kCloud, noise, 3, kT0).scan);
  EXPECT_FALSE(input.Take(Ros2SensorTopic::kCloud, nullptr, 0, kT0).scan);

  const Ros2TopicCounts& images = input.counts(Ros2SensorTopic::kImage);
  EXPECT_EQ(images.received, 2);
  EXPECT_EQ(images.malformed, 2);
  EXPECT_EQ(images.first_error, cut.error);
  EXPECT_EQ(input.counts(Ros2SensorTopic::kCloud).malformed, 2);
}

TEST(Ros2InputSettings, CameraInfoTopicFollowsImageTransportAndBadNamesAreRefused) {
  Ros2InputSettings s;
  EXPECT_EQ(s.CameraInfoTopic(), "/camera/camera_info");
  s.image_topic = "/front/image_raw/compressed";
  EXPECT_TRUE(s.compressed());
  EXPECT_EQ(s.CameraInfoTopic(), "/front/camera_info");
  EXPECT_EQ(s.Validate(), "");
  s.cloud_topic = "/lidar points";
  EXPECT_NE(s.Validate().find("cloud_topic"), std::string::npos);
  s.cloud_topic = "/points";
  EXPECT_FALSE(s.livox());
  s.cloud_type = "livox_ros_driver2/msg/CustomMsg";
  EXPECT_TRUE(s.livox());
  EXPECT_EQ(s.Validate(), "");
  s.cloud_type = "livox_ros_driver2/CustomMsg";
  EXPECT_EQ(s.Validate(),
            "cloud_type: 'livox_ros_driver2/CustomMsg' is not sensor_msgs/msg/PointCloud2 or "
            "livox_ros_driver2/msg/CustomMsg");
  s.cloud_type = "sensor_msgs/msg/PointCloud2";
  s.domain = 233;
  EXPECT_NE(s.Validate().find("domain"), std::string::npos);
  EXPECT_GE(ReceiveBufferBytes(Ros2InputSettings{}), size_t{60'000'000});
}

TEST(Ros2Names, TopicsAndTypesMapBothWays) {
  EXPECT_EQ(RosTopicToDds("/camera/image_raw"), "rt/camera/image_raw");
  EXPECT_EQ(RosTopicToDds("points"), "rt/points");
  EXPECT_THROW(RosTopicToDds("/"), std::invalid_argument);
  EXPECT_EQ(DdsTopicToRos("rt/camera/image_raw"), "/camera/image_raw");
  EXPECT_EQ(DdsTopicToRos("DCPSParticipant"), "DCPSParticipant");
  EXPECT_EQ(DdsTypeToRos("sensor_msgs::msg::dds_::PointCloud2_"), "sensor_msgs/msg/PointCloud2");
  EXPECT_EQ(RosTypeToDds("tf2_msgs/msg/TFMessage"), "tf2_msgs::msg::dds_::TFMessage_");
  EXPECT_EQ(DdsTypeToRos("fusecal::lcm_message"), "fusecal::lcm_message");
}

TEST(RosSensorEncode, CameraModelsRoundTripAndPanoramasAreRefused) {
  CameraParams fisheye = Pinhole();
  fisheye.model = "equidistant";
  fisheye.dist = {0.1, -0.02, 0.003, -0.0004, 0};
  for (const CameraParams& camera : {Pinhole(), fisheye}) {
    const CameraParams back = RosCameraInfoToParams(ToRosCameraInfo(camera, Header(kT0)));
    EXPECT_EQ(back.model, camera.model);
    EXPECT_EQ(back.dist, camera.dist);
    EXPECT_EQ(back.cx, camera.cx);
  }
  CameraParams panorama;
  panorama.model = "equirectangular";
  EXPECT_THROW(ToRosCameraInfo(panorama, Header(kT0)), std::runtime_error);
  EXPECT_EQ(UtimeToRosStamp(-1).sec, -1);
  EXPECT_EQ(UtimeToRosStamp(-1).nsec, 999999000u);
}

}  // namespace
}  // namespace fusecal
