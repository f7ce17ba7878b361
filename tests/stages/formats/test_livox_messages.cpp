// Livox's CustomMsg (livox_ros_driver2) and Livox's PointCloud2 layout: CDR and ROS 1 bytes laid out by
// hand from the serialization rules, round trips in both CDR byte orders, bytes that do not hold a
// message (cut short anywhere, a count that lies), and the conversion to fusecal's PointCloud: the two
// messages of one scan give the same points, intensities, rings and time offsets.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "stages/formats/livox_conversions.hpp"
#include "stages/formats/ros1_serialized.hpp"
#include "stages/formats/ros_cdr.hpp"
#include "stages/formats/ros_sensor_conversions.hpp"
#include "stages/formats/ros_sensor_frames.hpp"
#include "tests/support/cdr_writer.hpp"
#include "tests/support/point_cloud_expectations.hpp"

namespace fusecal {
namespace {

using testing::CdrByteOrder;
using testing::EncodeCdr;
using Bytes = std::vector<uint8_t>;

constexpr uint64_t kStampNs = 1700000000123456789ull;

RosLivoxCustomMsg SampleCustomMsg() {
  RosLivoxCustomMsg msg;
  msg.header = RosHeader{RosTime{1700000000, 123456789}, "livox_frame"};
  msg.timebase = kStampNs;
  msg.lidar_id = 1;
  msg.rsvd = {7, 8, 9};
  msg.points = {{0, 1.5f, -2.0f, 0.25f, 10, 0x10, 0},
                {50000, 3.0f, 4.0f, -5.0f, 200, 0x00, 3},
                {99000, std::numeric_limits<float>::quiet_NaN(), 1.0f, 1.0f, 5, 0, 1},
                {99500, 0.0f, 0.0f, 0.0f, 5, 0, 2}};
  msg.point_num = static_cast<uint32_t>(msg.points.size());
  return msg;
}

void Append(Bytes& bytes, const void* data, size_t n) {
  const auto* p = static_cast<const uint8_t*>(data);
  bytes.insert(bytes.end(), p, p + n);
}

template <typename T>
void Append(Bytes& bytes, T value) {
  Append(bytes, &value, sizeof(value));
}

void AppendPoint(Bytes& bytes, const RosLivoxPoint& p) {
  Append(bytes, p.offset_time);
  Append(bytes, p.x);
  Append(bytes, p.y);
  Append(bytes, p.z);
  for (uint8_t v : {p.reflectivity, p.tag, p.line}) bytes.push_back(v);
}

// Little-endian CDR by hand: offsets count from the end of the 4-byte encapsulation header.
Bytes GoldenCdr(const RosLivoxCustomMsg& msg) {
  Bytes bytes = {0x00, 0x01, 0x00, 0x00};
  Append(bytes, static_cast<int32_t>(msg.header.stamp.sec));  // body 0
  Append(bytes, msg.header.stamp.nsec);                       // body 4
  Append(bytes, static_cast<uint32_t>(msg.header.frame_id.size() + 1));
  Append(bytes, msg.header.frame_id.data(), msg.header.frame_id.size() + 1);  // body 12..24: "livox_frame\0"
  Append(bytes, msg.timebase);                                                // body 24, 8-aligned
  Append(bytes, msg.point_num);                                               // body 32
  bytes.push_back(msg.lidar_id);                                              // body 36
  Append(bytes, msg.rsvd.data(), 3);                                          // body 37..40
  Append(bytes, static_cast<uint32_t>(msg.points.size()));                    // body 40
  for (size_t i = 0; i < msg.points.size(); ++i) {
    if (i > 0) bytes.push_back(0);  // 19-byte points, each uint32 offset_time aligned to 4
    AppendPoint(bytes, msg.points[i]);
  }
  return bytes;
}

// ROS 1 by hand: packed, little-endian, a header with seq and no NUL after strings.
Bytes GoldenRos1(const RosLivoxCustomMsg& msg) {
  Bytes bytes;
  Append(bytes, uint32_t{42});
  Append(bytes, static_cast<uint32_t>(msg.header.stamp.sec));
  Append(bytes, msg.header.stamp.nsec);
  Append(bytes, static_cast<uint32_t>(msg.header.frame_id.size()));
  Append(bytes, msg.header.frame_id.data(), msg.header.frame_id.size());
  Append(bytes, msg.timebase);
  Append(bytes, msg.point_num);
  bytes.push_back(msg.lidar_id);
  Append(bytes, msg.rsvd.data(), 3);
  Append(bytes, static_cast<uint32_t>(msg.points.size()));
  for (const RosLivoxPoint& p : msg.points) AppendPoint(bytes, p);
  return bytes;
}

void ExpectSameMessage(const RosLivoxCustomMsg& got, const RosLivoxCustomMsg& want) {
  EXPECT_EQ(got.header.stamp.sec, want.header.stamp.sec);
  EXPECT_EQ(got.header.stamp.nsec, want.header.stamp.nsec);
  EXPECT_EQ(got.header.frame_id, want.header.frame_id);
  EXPECT_EQ(got.timebase, want.timebase);
  EXPECT_EQ(got.point_num, want.point_num);
  EXPECT_EQ(got.lidar_id, want.lidar_id);
  EXPECT_EQ(got.rsvd, want.rsvd);
  ASSERT_EQ(got.points.size(), want.points.size());
  for (size_t i = 0; i < got.points.size(); ++i) {
    EXPECT_EQ(got.points[i].offset_time, want.points[i].offset_time) << i;
    EXPECT_EQ(std::memcmp(&got.points[i].x, &want.points[i].x, 4), 0) << i;  // NaN too
    EXPECT_EQ(got.points[i].y, want.points[i].y) << i;
    EXPECT_EQ(got.points[i].z, want.points[i].z) << i;
    EXPECT_EQ(got.points[i].reflectivity, want.points[i].reflectivity) << i;
    EXPECT_EQ(got.points[i].tag, want.points[i].tag) << i;
    EXPECT_EQ(got.points[i].line, want.points[i].line) << i;
  }
}

std::string ErrorOf(const std::function<void()>& call) {
  try {
    call();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(LivoxCdr, AGoldenMessageLaidOutByHandDecodesAndIsWhatTheWriterWrites) {
  const RosLivoxCustomMsg msg = SampleCustomMsg();
  const Bytes golden = GoldenCdr(msg);
  ASSERT_EQ(golden.size(), 4u + 44 + 4 * 19 + 3);
  ExpectSameMessage(DecodeCdrLivoxCustomMsg(golden.data(), golden.size()), msg);
  EXPECT_EQ(EncodeCdr(msg), golden);
}

TEST(LivoxCdr, RoundTripsInBothByteOrders) {
  for (const CdrByteOrder order : {CdrByteOrder::kLittle, CdrByteOrder::kBig}) {
    const Bytes bytes = EncodeCdr(SampleCustomMsg(), order);
    ExpectSameMessage(DecodeCdrLivoxCustomMsg(bytes.data(), bytes.size()), SampleCustomMsg());
  }
}

TEST(LivoxCdr, AMessageCutShortAnywhereIsRefusedNamingTheField) {
  const Bytes bytes = EncodeCdr(SampleCustomMsg());
  for (size_t n = 0; n < bytes.size(); ++n) {
    const std::string error = ErrorOf([&] { DecodeCdrLivoxCustomMsg(bytes.data(), n); });
    EXPECT_NE(error.find("livox_ros_driver2/msg/CustomMsg"), std::string::npos) << n << ": " << error;
  }
  const std::string error = ErrorOf([&] { DecodeCdrLivoxCustomMsg(bytes.data(), bytes.size() - 1); });
  EXPECT_NE(error.find("field 'points' (4 elements) runs past the end"), std::string::npos) << error;
}

TEST(LivoxCdr, ACountThatLiesIsRefusedBeforeAnythingIsAllocated) {
  Bytes bytes = EncodeCdr(SampleCustomMsg());
  const uint32_t huge = 0xFFFFFFF0u;
  std::memcpy(&bytes[4 + 40], &huge, 4);
  const std::string error = ErrorOf([&] { DecodeCdrLivoxCustomMsg(bytes.data(), bytes.size()); });
  EXPECT_NE(error.find("field 'points' length 4294967280 runs past the end"), std::string::npos) << error;
}

TEST(LivoxRos1, AGoldenMessageDecodesAndOneCutShortAnywhereIsRefused) {
  const RosLivoxCustomMsg msg = SampleCustomMsg();
  const Bytes bytes = GoldenRos1(msg);
  ExpectSameMessage(DecodeRos1LivoxCustomMsg(bytes.data(), bytes.size()), msg);
  for (size_t n = 0; n < bytes.size(); ++n) {
    const std::string error = ErrorOf([&] { DecodeRos1LivoxCustomMsg(bytes.data(), n); });
    EXPECT_NE(error.find("livox_ros_driver2/CustomMsg: field '"), std::string::npos) << n << ": " << error;
  }
  Bytes lying = bytes;
  const uint32_t huge = 0xFFFFFFFFu;
  std::memcpy(&lying[4 + 4 + 4 + 4 + msg.header.frame_id.size() + 8 + 4 + 1 + 3], &huge, 4);
  const std::string error = ErrorOf([&] { DecodeRos1LivoxCustomMsg(lying.data(), lying.size()); });
  EXPECT_NE(error.find("field 'points' length 4294967295 runs past the end"), std::string::npos) << error;
}

// Every byte of both forms set to each of a few values: decoded and converted, or refused with an
// exception, never a crash (the fuzz entry ros_livox does this at random).
TEST(LivoxBytes, EveryByteCorruptedDecodesOrIsRefused) {
  const Bytes forms[] = {EncodeCdr(SampleCustomMsg()), EncodeCdr(SampleCustomMsg(), CdrByteOrder::kBig),
                         GoldenRos1(SampleCustomMsg())};
  for (size_t form = 0; form < 3; ++form)
    for (size_t i = 0; i < forms[form].size(); ++i)
      for (const uint8_t value : {0x00, 0x7F, 0x80, 0xFF}) {
        Bytes bytes = forms[form];
        bytes[i] = value;
        try {
          LivoxCustomMsgToPointCloud(form < 2 ? DecodeCdrLivoxCustomMsg(bytes.data(), bytes.size())
                                              : DecodeRos1LivoxCustomMsg(bytes.data(), bytes.size()));
        } catch (const std::runtime_error&) {
        }
      }
}

TEST(LivoxConversion, PointsReflectivityLinesAndTimesAfterTheStampWithoutReturnsDropped) {
  RosLivoxCustomMsg msg = SampleCustomMsg();
  msg.timebase = kStampNs + 1000;  // the first point 1 us after the stamp
  int dropped = -1;
  const PointCloud cloud = LivoxCustomMsgToPointCloud(msg, &dropped);
  EXPECT_EQ(dropped, 2);  // the NaN and the one at the origin
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(cloud.points[1], Eigen::Vector3f(3.0f, 4.0f, -5.0f));
  EXPECT_EQ(cloud.intensity, (std::vector<float>{10, 200}));
  EXPECT_EQ(cloud.ring, (std::vector<int16_t>{0, 3}));
  ASSERT_EQ(cloud.time_offset_s.size(), 2u);
  EXPECT_NEAR(cloud.time_offset_s[0], 1e-6, 1e-9);
  EXPECT_NEAR(cloud.time_offset_s[1], 51e-6, 1e-9);
  msg.header.stamp = RosTime{};
  EXPECT_TRUE(LivoxCustomMsgToPointCloud(msg).time_offset_s.empty());  // no stamp: the arrival time is no reference
}

TEST(LivoxConversion, APointNumThatIsNotTheNumberOfPointsIsAnError) {
  RosLivoxCustomMsg msg = SampleCustomMsg();
  msg.point_num = 24000;
  EXPECT_EQ(ErrorOf([&] { LivoxCustomMsgToPointCloud(msg); }), "CustomMsg point_num is 24000 but it holds 4 points");
}

TEST(LivoxConversion, AScanWithoutAReturnIsRefusedAsForPointCloud2) {
  RosLivoxCustomMsg msg = SampleCustomMsg();
  msg.points.resize(1);
  msg.points[0].x = std::numeric_limits<float>::infinity();
  msg.point_num = 1;
  RosSensorFrames frames;
  EXPECT_EQ(ErrorOf([&] { frames.Cloud(msg, 5); }), "no finite point in 1");
  msg.points[0].x = 1;
  const SensorScan scan = frames.Cloud(msg, 5);
  EXPECT_EQ(scan.utime, 1700000000123456);
  EXPECT_EQ(scan.frame_id, "livox_frame");
}

// livox_ros_driver2's PointCloud2 (xfer_format 0): x, y, z, intensity float32, tag, line uint8, timestamp
// float64 (the point's absolute time), packed into 26 bytes.
RosPointCloud2 LivoxPointCloud2(const RosLivoxCustomMsg& custom, double time_scale) {
  RosPointCloud2 msg;
  msg.header = custom.header;
  msg.height = 1;
  msg.width = static_cast<uint32_t>(custom.points.size());
  msg.fields = {{"x", 0, RosPointField::FLOAT32, 1},         {"y", 4, RosPointField::FLOAT32, 1},
                {"z", 8, RosPointField::FLOAT32, 1},         {"intensity", 12, RosPointField::FLOAT32, 1},
                {"tag", 16, RosPointField::UINT8, 1},        {"line", 17, RosPointField::UINT8, 1},
                {"timestamp", 18, RosPointField::FLOAT64, 1}};
  msg.point_step = 26;
  msg.row_step = 26 * msg.width;
  for (const RosLivoxPoint& p : custom.points) {
    Append(msg.data, p.x);
    Append(msg.data, p.y);
    Append(msg.data, p.z);
    Append(msg.data, static_cast<float>(p.reflectivity));
    msg.data.push_back(p.tag);
    msg.data.push_back(p.line);
    Append(msg.data, static_cast<double>(custom.timebase + p.offset_time) * time_scale);
  }
  return msg;
}

using testing::ExpectSameCloud;

TEST(LivoxPointCloud2, GivesWhatTheCustomMsgOfTheSameScanGives) {
  const RosLivoxCustomMsg custom = SampleCustomMsg();
  int dropped = -1;
  ExpectSameCloud(RosCloudToPointCloud(LivoxPointCloud2(custom, 1.0), &dropped), LivoxCustomMsgToPointCloud(custom));
  EXPECT_EQ(dropped, 2);
}

TEST(LivoxPointCloud2, TimestampsInSecondsOrFromPowerOnAreReadInTheirUnit) {
  RosLivoxCustomMsg custom = SampleCustomMsg();
  const PointCloud expected = LivoxCustomMsgToPointCloud(custom);
  ExpectSameCloud(RosCloudToPointCloud(LivoxPointCloud2(custom, 1e-9)), expected);  // Hesai: seconds
  custom.header.stamp = RosTime{95, 5000};  // an unsynchronised Livox: 95 s after power-on
  custom.timebase = 95000005000ull;
  ExpectSameCloud(RosCloudToPointCloud(LivoxPointCloud2(custom, 1.0)), expected);
  custom.header.stamp = RosTime{};
  EXPECT_TRUE(RosCloudToPointCloud(LivoxPointCloud2(custom, 1.0)).time_offset_s.empty());
}

TEST(LivoxPointCloud2, ANonFiniteTimestampIsAnError) {
  RosPointCloud2 msg = LivoxPointCloud2(SampleCustomMsg(), 1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(&msg.data[26 + 18], &nan, 8);
  EXPECT_EQ(ErrorOf([&] { RosCloudToPointCloud(msg); }), "PointCloud2 timestamp is not finite");
}

}  // namespace
}  // namespace fusecal
