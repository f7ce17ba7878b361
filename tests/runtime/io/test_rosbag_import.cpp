// `fusecal import rosbag` on bags this test writes with rosbag_storage itself: the four message types,
// the image encodings, cloud layouts, both CameraInfo models, missing and mistyped topics, and a
// simulated recording turned into a bag that calibrates to the same extrinsic as the original log.
#include <gtest/gtest.h>
#include <unistd.h>

#include <rosbag/bag.h>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "fusecal/camera_info_t.hpp"
#include "fusecal/image_t.hpp"
#include "fusecal/point_cloud_t.hpp"
#include "runtime/channels.hpp"
#include "runtime/io/importers/ros_messages.hpp"
#include "runtime/io/importers/rosbag.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/formats/camera_file.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/result_file.hpp"
#include "stages/formats/ros_sensor_conversions.hpp"
#include "tests/support/process_utils.hpp"

namespace fusecal {
namespace {

namespace fs = std::filesystem;
using testing::RunCommand;

const std::string kFusecal = FUSECAL_BIN;

std::string TempPath(const std::string& name) {
  return ::testing::TempDir() + "fusecal_rosbag_" + std::to_string(getpid()) + "_" + name;
}

ros::Time Stamp(int64_t utime) { return ros::Time(utime / 1000000, (utime % 1000000) * 1000); }

sensor_msgs::Image RawImage(const cv::Mat& pixels, const std::string& encoding, int64_t utime, int padding = 0) {
  sensor_msgs::Image msg;
  msg.header.stamp = Stamp(utime);
  msg.width = pixels.cols;
  msg.height = pixels.rows;
  msg.encoding = encoding;
  msg.step = static_cast<uint32_t>(pixels.cols * pixels.elemSize() + padding);
  msg.data.assign(static_cast<size_t>(msg.step) * pixels.rows, 0xAB);
  for (int r = 0; r < pixels.rows; ++r)
    std::memcpy(&msg.data[r * msg.step], pixels.ptr(r), pixels.cols * pixels.elemSize());
  return msg;
}

sensor_msgs::PointField Field(const std::string& name, uint32_t offset, uint8_t datatype) {
  sensor_msgs::PointField field;
  field.name = name;
  field.offset = offset;
  field.datatype = datatype;
  field.count = 1;
  return field;
}

// x, y, z, intensity, ring as float32 x4 + uint16 (the Velodyne driver's layout), `width` x `height`.
sensor_msgs::PointCloud2 VelodyneCloud(const PointCloud& cloud, int64_t utime, int height = 1) {
  sensor_msgs::PointCloud2 msg;
  msg.header.stamp = Stamp(utime);
  msg.height = height;
  msg.width = static_cast<uint32_t>(cloud.size() / height);
  msg.fields = {Field("x", 0, 7), Field("y", 4, 7), Field("z", 8, 7), Field("intensity", 12, 7), Field("ring", 16, 4)};
  msg.point_step = 22;  // 4 bytes of padding after the ring, as real drivers have
  msg.row_step = msg.point_step * msg.width;
  msg.data.assign(static_cast<size_t>(msg.row_step) * height, 0);
  for (size_t i = 0; i < cloud.size(); ++i) {
    uint8_t* p = &msg.data[i * msg.point_step];
    std::memcpy(p, cloud.points[i].data(), 12);
    const float intensity = cloud.HasIntensity() ? cloud.intensity[i] : 0.0f;
    std::memcpy(p + 12, &intensity, 4);
    const uint16_t ring = cloud.ring.empty() ? 0 : static_cast<uint16_t>(cloud.ring[i]);
    std::memcpy(p + 16, &ring, 2);
  }
  return msg;
}

sensor_msgs::CameraInfo PlumbBob(int width, int height) {
  sensor_msgs::CameraInfo info;
  info.width = width;
  info.height = height;
  info.distortion_model = "plumb_bob";
  info.D = {-0.2, 0.05, 0.001, -0.002, 0.0};
  info.K = {400, 0, 31.5, 0, 401, 23.5, 0, 0, 1};
  return info;
}

struct LogContents {
  std::vector<image_t> images;
  std::vector<point_cloud_t> scans;
  std::vector<camera_info_t> cameras;
  std::vector<int64_t> utimes;  // of every event, in file order
};

LogContents ReadLog(const std::string& path) {
  LogContents contents;
  LogReader reader(path);
  while (auto event = reader.Next()) {
    contents.utimes.push_back(event->utime);
    const int size = static_cast<int>(event->data.size());
    if (event->channel == channels::kCameraImage.name) {
      contents.images.emplace_back();
      contents.images.back().decode(event->data.data(), 0, size);
    } else if (event->channel == channels::kLidarScan.name) {
      contents.scans.emplace_back();
      contents.scans.back().decode(event->data.data(), 0, size);
    } else if (event->channel == channels::kCameraInfo.name) {
      contents.cameras.emplace_back();
      contents.cameras.back().decode(event->data.data(), 0, size);
    }
  }
  EXPECT_TRUE(reader.problems().empty());
  return contents;
}

TEST(RosbagImport, TheFourMessageTypesBecomeALogInHeaderStampOrder) {
  const std::string bag_path = TempPath("four.bag"), log_path = TempPath("four.lcmlog");
  const int64_t t0 = 1700000000000000;
  PointCloud cloud;
  for (int i = 0; i < 6; ++i) {
    cloud.points.emplace_back(1.0f + i, 0.5f, -0.25f);
    cloud.intensity.push_back(10.0f * i);
    cloud.ring.push_back(static_cast<int16_t>(i % 2));
  }
  {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
    bag.write("/camera/camera_info", Stamp(t0), PlumbBob(64, 48));
    for (int k = 0; k < 3; ++k) {
      const cv::Mat pixels(48, 64, CV_8UC3, cv::Scalar(10 * k, 20, 30));
      // The scans arrive 300 ms late, so the bag's order is not the stamps' order.
      bag.write("/camera/image_raw", Stamp(t0 + k * 100000 + 5000), RawImage(pixels, "bgr8", t0 + k * 100000, 3));
      bag.write("/velodyne_points", Stamp(t0 + k * 100000 + 300000), VelodyneCloud(cloud, t0 + k * 100000 + 20000, 2));
    }
    std::vector<uint8_t> png;
    cv::imencode(".png", cv::Mat(48, 64, CV_8UC1, cv::Scalar(77)), png);
    sensor_msgs::CompressedImage compressed;
    compressed.header.stamp = Stamp(t0 + 400000);
    compressed.format = "mono8; png compressed";
    compressed.data = png;
    bag.write("/camera/image_raw/compressed", Stamp(t0 + 400000), compressed);
  }
  RosbagImportOptions options;
  options.image_topic = "/camera/image_raw";
  options.cloud_topic = "/velodyne_points";
  const ImportReport report = ImportRosbag(bag_path, log_path, options);
  for (const auto& warning : report.warnings) ADD_FAILURE() << warning;
  EXPECT_EQ(report.images, 3);
  EXPECT_EQ(report.scans, 3);

  const LogContents log = ReadLog(log_path);
  ASSERT_EQ(log.cameras.size(), 1u);
  const CameraParams camera = CameraFromMsg(log.cameras[0]);
  EXPECT_EQ(camera.model, "pinhole");
  EXPECT_EQ(camera.fy, 401);
  EXPECT_EQ(camera.dist[3], -0.002);
  EXPECT_TRUE(std::is_sorted(log.utimes.begin(), log.utimes.end()));
  ASSERT_EQ(log.images.size(), 3u);
  EXPECT_EQ(log.images[0].utime, t0);
  EXPECT_EQ(ImageToMat(log.images[2]).at<cv::Vec3b>(47, 63), cv::Vec3b(20, 20, 30));  // padding left out
  ASSERT_EQ(log.scans.size(), 3u);
  EXPECT_EQ(log.scans[1].utime, t0 + 120000);
  const PointCloud back = CloudFromMsg(log.scans[1]);
  ASSERT_EQ(back.size(), cloud.size());
  EXPECT_EQ(back.points[4], cloud.points[4]);
  EXPECT_EQ(back.intensity[5], 50.0f);
  EXPECT_EQ(back.ring[3], 1);

  // The compressed topic finds /camera/camera_info two levels up; PNG bytes are kept as they are.
  options.image_topic = "/camera/image_raw/compressed";
  EXPECT_EQ(ImportRosbag(bag_path, log_path, options).images, 1);
  const LogContents compressed_log = ReadLog(log_path);
  ASSERT_EQ(compressed_log.images.size(), 1u);
  EXPECT_EQ(compressed_log.images[0].encoding, "png");
  EXPECT_EQ(ImageToMat(compressed_log.images[0]).at<uint8_t>(5, 5), 77);
  EXPECT_EQ(compressed_log.cameras.size(), 1u);
}

TEST(RosbagImport, ImageEncodingsBecomeGreyOrBgr) {
  SixteenBitScaler scaler;
  const cv::Mat rgb(2, 3, CV_8UC3, cv::Scalar(1, 2, 3));  // as R, G, B
  EXPECT_EQ(RosImageToMat(FromRos1(RawImage(rgb, "rgb8", 0)), scaler).at<cv::Vec3b>(1, 2), cv::Vec3b(3, 2, 1));
  const cv::Mat grey(2, 3, CV_8UC1, cv::Scalar(9));
  const cv::Mat mono = RosImageToMat(FromRos1(RawImage(grey, "mono8", 0, 5)), scaler);
  EXPECT_EQ(mono.type(), CV_8UC1);
  EXPECT_EQ(mono.at<uint8_t>(1, 2), 9);
  // 12-bit data in 16-bit pixels: the first image fixes a shift of 4 for the recording.
  cv::Mat sixteen(2, 3, CV_16UC1, cv::Scalar(4095));
  sixteen.at<uint16_t>(0, 0) = 1600;
  const cv::Mat eight = RosImageToMat(FromRos1(RawImage(sixteen, "mono16", 0)), scaler);
  EXPECT_EQ(scaler.shift(), 4);
  EXPECT_EQ(eight.at<uint8_t>(0, 0), 100);
  EXPECT_EQ(eight.at<uint8_t>(1, 1), 255);
  sensor_msgs::Image big_endian = RawImage(cv::Mat(1, 1, CV_16UC1, cv::Scalar(0x0100)), "16UC1", 0);
  big_endian.is_bigendian = 1;  // bytes 00 01: the value 1
  EXPECT_EQ(RosImageToMat(FromRos1(big_endian), scaler).at<uint8_t>(0, 0), 0);
  cv::Mat bayer(4, 4, CV_8UC1, cv::Scalar(0));
  EXPECT_EQ(RosImageToMat(FromRos1(RawImage(bayer, "bayer_rggb8", 0)), scaler).type(), CV_8UC3);

  try {
    RosImageToMat(FromRos1(RawImage(grey, "yuv422", 0)), scaler);
    FAIL() << "yuv422 accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("yuv422"), std::string::npos) << e.what();
  }
  sensor_msgs::Image short_data = RawImage(grey, "mono8", 0);
  short_data.data.resize(4);
  EXPECT_THROW(RosImageToMat(FromRos1(short_data), scaler), std::runtime_error);
}

TEST(RosbagImport, CloudsOfAnyFieldLayoutDropPointsWithoutReturn) {
  // z, y, x as float64 in reverse order, intensity as uint8, organised 2 x 2 with a NaN and a zero point.
  sensor_msgs::PointCloud2 msg;
  msg.height = 2;
  msg.width = 2;
  msg.fields = {Field("z", 0, 8), Field("y", 8, 8), Field("x", 16, 8), Field("i", 24, 2)};
  msg.point_step = 25;
  msg.row_step = 60;  // 10 bytes of row padding
  msg.data.assign(120, 0);
  const double points[4][3] = {{1, 2, 3}, {NAN, 0, 0}, {0, 0, 0}, {-4, 5, 6.5}};
  for (int k = 0; k < 4; ++k) {
    uint8_t* p = &msg.data[(k / 2) * msg.row_step + (k % 2) * msg.point_step];
    for (int axis = 0; axis < 3; ++axis) std::memcpy(p + 16 - 8 * axis, &points[k][axis], 8);
    p[24] = static_cast<uint8_t>(100 + k);
  }
  int dropped = 0;
  const PointCloud cloud = RosCloudToPointCloud(FromRos1(msg), &dropped);
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(dropped, 2);
  EXPECT_EQ(cloud.points[1], Eigen::Vector3f(-4, 5, 6.5));
  EXPECT_EQ(cloud.intensity[1], 103.0f);

  sensor_msgs::PointCloud2 without_z = msg;
  without_z.fields.erase(without_z.fields.begin());
  try {
    RosCloudToPointCloud(FromRos1(without_z));
    FAIL() << "a cloud without z accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("y, x, i"), std::string::npos) << e.what();
  }
  sensor_msgs::PointCloud2 truncated = msg;
  truncated.data.resize(100);
  EXPECT_THROW(RosCloudToPointCloud(FromRos1(truncated)), std::runtime_error);
}

// Sizes and offsets are checked in 64 bits: an offset near 2^32 does not wrap round to a small sum that
// passes, and width x height does not wrap round to 0.
TEST(RosbagImport, OffsetsAndSizesNear32BitsAreRefusedNotWrapped) {
  sensor_msgs::PointCloud2 msg;
  msg.height = 1;
  msg.width = 1;
  msg.fields = {Field("x", 0, 7), Field("y", 4, 7), Field("z", 4294967294u, 7)};
  msg.point_step = 12;
  msg.row_step = 12;
  msg.data.assign(12, 0);
  try {
    RosCloudToPointCloud(FromRos1(msg));
    FAIL() << "a field at offset 2^32 - 2 was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'z' lies beyond point_step"), std::string::npos) << e.what();
  }
  sensor_msgs::PointCloud2 wraps = msg;
  wraps.fields[2].offset = 8;
  wraps.width = 65536;
  wraps.height = 65536;  // width x height is 2^32: 0 in 32 bits
  wraps.point_step = 0;
  EXPECT_THROW(RosCloudToPointCloud(FromRos1(wraps)), std::runtime_error);
}

TEST(RosbagImport, CameraInfoPlumbBobAndEquidistant) {
  const CameraParams pinhole = RosCameraInfoToParams(FromRos1(PlumbBob(640, 480)));
  EXPECT_EQ(pinhole.model, "pinhole");
  EXPECT_EQ(pinhole.cx, 31.5);
  EXPECT_EQ(pinhole.dist[0], -0.2);
  sensor_msgs::CameraInfo fisheye = PlumbBob(1024, 1024);
  fisheye.distortion_model = "equidistant";
  fisheye.D = {0.02, -0.006, 0.0009, -0.0002};
  const CameraParams equidistant = RosCameraInfoToParams(FromRos1(fisheye));
  EXPECT_EQ(equidistant.model, "equidistant");
  EXPECT_EQ(equidistant.dist[3], -0.0002);
  EXPECT_NO_THROW(MakeCameraModel(equidistant));
  sensor_msgs::CameraInfo uncalibrated = PlumbBob(640, 480);
  uncalibrated.K = {};
  EXPECT_THROW(RosCameraInfoToParams(FromRos1(uncalibrated)), std::runtime_error);
  sensor_msgs::CameraInfo unknown = PlumbBob(640, 480);
  unknown.distortion_model = "fov";
  EXPECT_THROW(RosCameraInfoToParams(FromRos1(unknown)), std::runtime_error);
}

TEST(RosbagImport, AMissingOrMistypedTopicIsAnErrorListingTheBagsTopics) {
  const std::string bag_path = TempPath("topics.bag"), log_path = TempPath("topics.lcmlog");
  {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
    bag.write("/cam/image", Stamp(1000000), RawImage(cv::Mat(4, 4, CV_8UC1, cv::Scalar(1)), "mono8", 1000000));
    bag.write("/cam/camera_info", Stamp(1000000), PlumbBob(4, 4));
  }
  const std::string base = kFusecal + " import rosbag " + bag_path + " --out " + log_path;
  const auto missing = RunCommand(base + " --image-topic /cam/image --cloud-topic /points 2>&1");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("no topic /points"), std::string::npos) << missing.output;
  EXPECT_NE(missing.output.find("/cam/image (sensor_msgs/Image)"), std::string::npos) << missing.output;
  EXPECT_NE(missing.output.find("/cam/camera_info (sensor_msgs/CameraInfo)"), std::string::npos) << missing.output;
  const auto mistyped = RunCommand(base + " --image-topic /cam/camera_info --cloud-topic /cam/image 2>&1");
  EXPECT_EQ(mistyped.exit_code, 1);
  EXPECT_NE(mistyped.output.find("topic /cam/camera_info is sensor_msgs/CameraInfo"), std::string::npos)
      << mistyped.output;
  const auto unnamed = RunCommand(base + " 2>&1");
  EXPECT_EQ(unnamed.exit_code, 1);
  EXPECT_NE(unnamed.output.find("name the image topic"), std::string::npos) << unnamed.output;
  EXPECT_FALSE(fs::exists(log_path));
  std::ofstream(TempPath("not.bag")) << "not a bag";
  const auto garbage = RunCommand(kFusecal + " import rosbag " + TempPath("not.bag") +
                                  " --image-topic /a --cloud-topic /b --out " + log_path + " 2>&1");
  EXPECT_EQ(garbage.exit_code, 1);
  EXPECT_NE(garbage.output.find("not a readable ROS 1 bag"), std::string::npos) << garbage.output;
}

// A simulated recording as a driver would have recorded it: JPEG CompressedImage, Velodyne-layout
// PointCloud2, arriving 20-40 ms after their stamps. The camera goes in as a file (an equirectangular
// panorama has no CameraInfo model).
void WriteLogAsBag(const std::string& log_path, const std::string& bag_path, const std::string& camera_path) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
  LogReader reader(log_path);
  while (auto event = reader.Next()) {
    const int size = static_cast<int>(event->data.size());
    if (event->channel == channels::kCameraImage.name) {
      image_t image;
      image.decode(event->data.data(), 0, size);
      ASSERT_EQ(image.encoding, "jpeg");
      sensor_msgs::CompressedImage msg;
      msg.header.stamp = Stamp(image.utime);
      msg.format = "bgr8; jpeg compressed bgr8";
      msg.data = image.data;
      bag.write("/camera/image_raw/compressed", Stamp(image.utime + 40000), msg);
    } else if (event->channel == channels::kLidarScan.name) {
      point_cloud_t scan;
      scan.decode(event->data.data(), 0, size);
      bag.write("/velodyne_points", Stamp(scan.utime + 20000), VelodyneCloud(CloudFromMsg(scan), scan.utime));
    } else if (event->channel == channels::kCameraInfo.name) {
      camera_info_t info;
      info.decode(event->data.data(), 0, size);
      std::ofstream(camera_path) << CameraToYaml(CameraFromMsg(info));
    }
  }
}

TEST(RosbagImport, ASimulatedRecordingAsABagCalibratesLikeTheOriginalLog) {
  const std::string log_path = TempPath("small.lcmlog"), bag_path = TempPath("small.bag"),
                    camera_path = TempPath("camera.yaml"), imported = TempPath("imported.lcmlog");
  ASSERT_EQ(RunCommand(kFusecal + " simulate --scenario " + std::string(SCENARIO_DIR) + "/small-equirect.yaml --out " +
                       log_path + " > /dev/null")
                .exit_code,
            0);
  WriteLogAsBag(log_path, bag_path, camera_path);
  const auto import = RunCommand(kFusecal + " import rosbag " + bag_path +
                                 " --image-topic /camera/image_raw/compressed --cloud-topic /velodyne_points"
                                 " --camera " +
                                 camera_path + " --out " + imported + " 2>&1");
  ASSERT_EQ(import.exit_code, 0) << import.output;
  const LogContents original = ReadLog(log_path), back = ReadLog(imported);
  ASSERT_EQ(back.images.size(), original.images.size());
  ASSERT_EQ(back.scans.size(), original.scans.size());
  for (size_t i = 0; i < back.images.size(); ++i) {
    EXPECT_EQ(back.images[i].utime, original.images[i].utime);
    EXPECT_EQ(back.images[i].data, original.images[i].data);
  }
  for (size_t i = 0; i < back.scans.size(); ++i) {
    EXPECT_EQ(back.scans[i].utime, original.scans[i].utime);
    EXPECT_EQ(back.scans[i].x, original.scans[i].x);
  }
  for (const std::string& log : {log_path, imported})
    ASSERT_EQ(RunCommand(kFusecal + " calibrate --log " + log + " --out " + log + ".out > /dev/null 2>&1").exit_code,
              0);
  const CalibrationResult expected = ReadResultFile(log_path + ".out/extrinsic.yaml");
  const CalibrationResult result = ReadResultFile(imported + ".out/extrinsic.yaml");
  EXPECT_EQ(result.status, "converged");
  EXPECT_LT((result.T_camera_lidar.matrix() - expected.T_camera_lidar.matrix()).cwiseAbs().maxCoeff(), 1e-6);
}

}  // namespace
}  // namespace fusecal
