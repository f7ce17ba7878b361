// `fusecal import rosbag` on ROS 2 bags: one recording written as a ROS 1 bag (rosbag_storage), as MCAP
// and as sqlite3 (the test writers of tests/support, messages in CDR) imports to the same log; the CDR and
// ROS 1 forms of a message convert alike; a missing or mistyped topic lists the bag's ROS 2 types; an
// unusable message is skipped and counted.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <variant>

#include "runtime/io/importers/ros_messages.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/formats/ros_cdr.hpp"
#include "stages/formats/ros_sensor_conversions.hpp"
#include "stages/formats/ros_sensor_encode.hpp"
#include "tests/support/db3_test_writer.hpp"
#include "tests/support/process_utils.hpp"
#include "tests/support/recorded_bags.hpp"
#include "tests/support/ros1_bag_writer.hpp"

namespace fusecal {
namespace {

namespace fs = std::filesystem;
using testing::CdrByteOrder;
using testing::EncodeCdr;
using testing::RecordedMessage;
using testing::RosAnyMessage;
using testing::RunCommand;
using testing::SerializeCdr;
using testing::ToRos1;
using testing::ToRos2Bag;
using testing::WriteDb3Bag;
using testing::WriteMcapBag;
using testing::WriteRos1Bag;

const std::string kFusecal = FUSECAL_BIN;
const int64_t kT0 = 1700000000000000;

std::string TempPath(const std::string& name) {
  return ::testing::TempDir() + "fusecal_rosbag2_" + std::to_string(getpid()) + "_" + name;
}

RosImage RawImage(const cv::Mat& pixels, const std::string& encoding, int64_t utime, int padding = 0) {
  RosImage msg;
  msg.header = RosHeader{UtimeToRosStamp(utime), "camera"};
  msg.width = static_cast<uint32_t>(pixels.cols);
  msg.height = static_cast<uint32_t>(pixels.rows);
  msg.encoding = encoding;
  msg.step = static_cast<uint32_t>(pixels.cols * pixels.elemSize() + padding);
  msg.data.assign(static_cast<size_t>(msg.step) * pixels.rows, 0xAB);
  for (int r = 0; r < pixels.rows; ++r)
    std::memcpy(&msg.data[r * msg.step], pixels.ptr(r), pixels.cols * pixels.elemSize());
  return msg;
}

// x, y, z, intensity as float32 and ring as uint16 (the Velodyne driver's layout), 4 bytes of padding.
RosPointCloud2 VelodyneCloud(int64_t utime, int height = 2) {
  RosPointCloud2 msg;
  msg.header = RosHeader{UtimeToRosStamp(utime), "velodyne"};
  msg.height = static_cast<uint32_t>(height);
  msg.width = 3;
  msg.fields = {{"x", 0, RosPointField::FLOAT32, 1},
                {"y", 4, RosPointField::FLOAT32, 1},
                {"z", 8, RosPointField::FLOAT32, 1},
                {"intensity", 12, RosPointField::FLOAT32, 1},
                {"ring", 16, RosPointField::UINT16, 1}};
  msg.point_step = 22;
  msg.row_step = msg.point_step * msg.width;
  msg.data.assign(static_cast<size_t>(msg.row_step) * msg.height, 0);
  for (uint32_t i = 0; i < msg.width * msg.height; ++i) {
    const float values[4] = {1.0f + i, 0.5f, -0.25f, 10.0f * i};
    const uint16_t ring = static_cast<uint16_t>(i % 2);
    std::memcpy(&msg.data[i * msg.point_step], values, 16);
    std::memcpy(&msg.data[i * msg.point_step + 16], &ring, 2);
  }
  return msg;
}

RosCameraInfo PlumbBob(int width, int height) {
  RosCameraInfo info;
  info.header.frame_id = "camera";
  info.width = static_cast<uint32_t>(width);
  info.height = static_cast<uint32_t>(height);
  info.distortion_model = "plumb_bob";
  info.D = {-0.2, 0.05, 0.001, -0.002, 0.0};
  info.K = {400, 0, 31.5, 0, 401, 23.5, 0, 0, 1};
  return info;
}

// Clouds big-endian, the rest little-endian: both byte orders in one bag.
RecordedMessage Recorded(const std::string& topic, int64_t arrival_utime, RosAnyMessage msg) {
  const CdrByteOrder order = msg.index() == 2 ? CdrByteOrder::kBig : CdrByteOrder::kLittle;
  return RecordedMessage{topic, arrival_utime, std::move(msg), {}, order};
}

// The recording of RosbagImport.TheFourMessageTypesBecomeALogInHeaderStampOrder: a CameraInfo, three
// padded bgr8 images, three clouds arriving 300 ms late (so arrival order is not stamp order), one PNG.
std::vector<RecordedMessage> FourTypes() {
  std::vector<RecordedMessage> recording;
  recording.push_back(Recorded("/camera/camera_info", kT0, PlumbBob(64, 48)));
  for (int k = 0; k < 3; ++k) {
    const cv::Mat pixels(48, 64, CV_8UC3, cv::Scalar(10 * k, 20, 30));
    recording.push_back(
        Recorded("/camera/image_raw", kT0 + k * 100000 + 5000, RawImage(pixels, "bgr8", kT0 + k * 100000, 3)));
    recording.push_back(
        Recorded("/velodyne_points", kT0 + k * 100000 + 300000, VelodyneCloud(kT0 + k * 100000 + 20000)));
  }
  RosCompressedImage compressed;
  compressed.header = RosHeader{UtimeToRosStamp(kT0 + 400000), "camera"};
  compressed.format = "mono8; png compressed";
  cv::imencode(".png", cv::Mat(48, 64, CV_8UC1, cv::Scalar(77)), compressed.data);
  recording.push_back(Recorded("/camera/image_raw/compressed", kT0 + 400000, compressed));
  return recording;
}

std::vector<LogEvent> ReadEvents(const std::string& path) {
  std::vector<LogEvent> events;
  LogReader reader(path);
  while (auto event = reader.Next()) events.push_back(*event);
  EXPECT_TRUE(reader.problems().empty());
  return events;
}

// Imports with the CLI; returns its output (stdout and stderr).
std::string Import(const std::string& bag, const std::string& image_topic, const std::string& log,
                   int expected_exit = 0) {
  const auto run = RunCommand(kFusecal + " import rosbag " + bag + " --image-topic " + image_topic +
                              " --cloud-topic /velodyne_points --out " + log + " 2>&1");
  EXPECT_EQ(run.exit_code, expected_exit) << run.output;
  return run.output;
}

void ExpectSameLog(const std::string& expected_path, const std::string& path) {
  const std::vector<LogEvent> expected = ReadEvents(expected_path), events = ReadEvents(path);
  ASSERT_EQ(events.size(), expected.size()) << path;
  for (size_t i = 0; i < events.size(); ++i) {
    SCOPED_TRACE(path + ": event " + std::to_string(i) + " " + expected[i].channel);
    EXPECT_EQ(events[i].channel, expected[i].channel);
    EXPECT_EQ(events[i].utime, expected[i].utime);
    EXPECT_TRUE(events[i].data == expected[i].data);
  }
}

TEST(Rosbag2Import, McapAndDb3ImportToTheLogOfTheSameRos1Bag) {
  const std::vector<RecordedMessage> recording = FourTypes();
  const std::string ros1 = TempPath("four.bag"), mcap = TempPath("four.mcap"), db3 = TempPath("four.db3");
  WriteRos1Bag(ros1, recording);
  WriteMcapBag(mcap, recording);
  WriteDb3Bag(db3, recording);
  // A bag folder as `ros2 bag record` leaves it: metadata.yaml beside the storage file.
  const std::string folder = TempPath("four_folder");
  fs::create_directories(folder);
  fs::copy_file(mcap, folder + "/four_0.mcap", fs::copy_options::overwrite_existing);
  {
    std::vector<testing::BagTopic> topics;
    std::vector<testing::BagMessage> messages;
    ToRos2Bag(recording, topics, messages);
    testing::WriteRosbag2Metadata(folder, "mcap", {"four_0.mcap"}, topics, messages);
  }
  for (const std::string image_topic : {"/camera/image_raw", "/camera/image_raw/compressed"}) {
    SCOPED_TRACE(image_topic);
    const std::string expected = TempPath("ros1.lcmlog");
    const std::string output = Import(ros1, image_topic, expected);
    EXPECT_EQ(output.find("warning"), std::string::npos) << output;
    EXPECT_EQ(ReadEvents(expected).size(), image_topic == "/camera/image_raw" ? 7u : 5u);  // + the camera
    for (const std::string& bag : {mcap, db3, folder}) {
      const std::string log = TempPath("ros2.lcmlog");
      const std::string ros2_output = Import(bag, image_topic, log);
      EXPECT_EQ(ros2_output.find("warning"), std::string::npos) << ros2_output;
      ExpectSameLog(expected, log);
    }
  }
}

TEST(Rosbag2Import, CdrAndRos1MessagesConvertAlike) {
  SixteenBitScaler ros1_scaler, cdr_scaler;
  cv::Mat sixteen(3, 5, CV_16UC1);
  cv::randu(sixteen, 0, 4096);
  RosImage big_endian = RawImage(sixteen, "mono16", kT0, 2);
  big_endian.is_bigendian = 1;
  for (const RosImage& image : {RawImage(cv::Mat(4, 6, CV_8UC3, cv::Scalar(1, 2, 3)), "rgb8", kT0, 1), big_endian,
                                RawImage(cv::Mat(4, 4, CV_8UC1, cv::Scalar(50)), "bayer_grbg8", kT0)}) {
    SCOPED_TRACE(image.encoding);
    const cv::Mat ros1 = RosImageToMat(FromRos1(ToRos1(image)), ros1_scaler);
    const std::vector<uint8_t> bytes = EncodeCdr(image, CdrByteOrder::kBig);
    const cv::Mat cdr = RosImageToMat(DecodeCdrImage(bytes.data(), bytes.size()), cdr_scaler);
    ASSERT_EQ(cdr.type(), ros1.type());
    EXPECT_EQ(cv::norm(cdr, ros1, cv::NORM_INF), 0.0);
  }
  RosPointCloud2 cloud = VelodyneCloud(kT0);
  const float nan = NAN;
  std::memcpy(&cloud.data[cloud.point_step], &nan, 4);  // the second point has no return
  int ros1_dropped = 0, cdr_dropped = 0;
  const PointCloud ros1 = RosCloudToPointCloud(FromRos1(ToRos1(cloud)), &ros1_dropped);
  const std::vector<uint8_t> bytes = EncodeCdr(cloud);
  const PointCloud cdr = RosCloudToPointCloud(DecodeCdrPointCloud2(bytes.data(), bytes.size()), &cdr_dropped);
  EXPECT_EQ(cdr_dropped, 1);
  EXPECT_EQ(cdr_dropped, ros1_dropped);
  EXPECT_EQ(cdr.points, ros1.points);
  EXPECT_EQ(cdr.intensity, ros1.intensity);
  EXPECT_EQ(cdr.ring, ros1.ring);
}

TEST(Rosbag2Import, AMissingOrMistypedTopicListsTheBagsRos2Types) {
  const std::string bag = TempPath("topics.mcap"), log = TempPath("topics.lcmlog");
  WriteMcapBag(bag, {{"/cam/image", 1000000, RawImage(cv::Mat(4, 4, CV_8UC1, cv::Scalar(1)), "mono8", 1000000), {}},
                     {"/cam/camera_info", 1000000, PlumbBob(4, 4), {}}});
  const std::string base = kFusecal + " import rosbag " + bag + " --out " + log;
  const auto missing = RunCommand(base + " --image-topic /cam/image --cloud-topic /points 2>&1");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("no topic /points"), std::string::npos) << missing.output;
  EXPECT_NE(missing.output.find("/cam/image (sensor_msgs/msg/Image)"), std::string::npos) << missing.output;
  EXPECT_NE(missing.output.find("/cam/camera_info (sensor_msgs/msg/CameraInfo)"), std::string::npos) << missing.output;
  const auto mistyped = RunCommand(base + " --image-topic /cam/image --cloud-topic /cam/image 2>&1");
  EXPECT_EQ(mistyped.exit_code, 1);
  EXPECT_NE(mistyped.output.find("topic /cam/image is sensor_msgs/msg/Image, the cloud must be "
                                 "sensor_msgs/msg/PointCloud2"),
            std::string::npos)
      << mistyped.output;
  const auto unnamed = RunCommand(base + " 2>&1");
  EXPECT_EQ(unnamed.exit_code, 1);
  EXPECT_NE(unnamed.output.find("name the image topic (sensor_msgs/msg/Image or sensor_msgs/msg/CompressedImage)"),
            std::string::npos)
      << unnamed.output;
  EXPECT_FALSE(fs::exists(log));
}

TEST(Rosbag2Import, AnUnusableMessageIsSkippedAndCounted) {
  std::vector<RecordedMessage> recording = FourTypes();
  recording.pop_back();  // the PNG
  // The second image cut short, the third in XCDR2, the last cloud with a data length that lies.
  std::vector<uint8_t> cut = SerializeCdr(recording[3]);
  cut.resize(cut.size() / 2);
  recording[3].cdr = cut;
  std::vector<uint8_t> cdr2 = SerializeCdr(recording[5]);
  cdr2[1] = 0x07;
  recording[5].cdr = cdr2;
  std::vector<uint8_t> lying = SerializeCdr(recording[6]);
  const size_t data_length_at = lying.size() - 1 - std::get<RosPointCloud2>(recording[6].msg).data.size() - 4;
  for (int i = 0; i < 4; ++i) lying[data_length_at + i] = 0xFF;
  recording[6].cdr = lying;
  std::get<RosPointCloud2>(recording[2].msg).header.stamp = RosTime{};  // no stamp: the bag's time is used
  const std::string bag = TempPath("damaged.db3"), log = TempPath("damaged.lcmlog");
  WriteDb3Bag(bag, recording);
  const std::string output = Import(bag, "/camera/image_raw", log);
  EXPECT_NE(output.find("1 images, 2 scans"), std::string::npos) << output;
  EXPECT_NE(output.find("/camera/image_raw: 2 message(s) skipped, the first: sensor_msgs/msg/Image: field 'data' "
                        "length 9360 runs past the end of the "),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("/velodyne_points: 1 message(s) skipped, the first: sensor_msgs/msg/PointCloud2: field "
                        "'data' length 4294967295 runs past the end of the " +
                        std::to_string(lying.size()) + "-byte message at offset " + std::to_string(data_length_at)),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("1 message(s) had a zero header stamp; their bag time was used"), std::string::npos) << output;
  const std::vector<LogEvent> events = ReadEvents(log);
  ASSERT_EQ(events.size(), 4u);
  EXPECT_EQ(events.back().utime, recording[2].arrival_utime);
}

}  // namespace
}  // namespace fusecal
