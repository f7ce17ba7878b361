// ROS 2 sensor messages in CDR (formats/ros_cdr.hpp): round trips through the test writer in both byte
// orders, golden bytes laid out by hand from the CDR rules (so that the writer and the reader cannot share
// one mistake), and bytes that do not hold a message: cut short anywhere, lengths that lie, another
// encapsulation, nothing at all. Each is an exception naming the message type, the field and the offset.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "stages/formats/ros_cdr.hpp"
#include "stages/formats/ros_sensor_conversions.hpp"
#include "tests/support/cdr_writer.hpp"

namespace fusecal {
namespace {

using testing::CdrByteOrder;
using testing::EncodeCdr;
using Bytes = std::vector<uint8_t>;

const CdrByteOrder kOrders[] = {CdrByteOrder::kLittle, CdrByteOrder::kBig};

RosHeader Header(const std::string& frame_id) { return RosHeader{RosTime{1700000000, 123456789}, frame_id}; }

RosPointCloud2 SampleCloud() {
  RosPointCloud2 msg;
  msg.header = Header("velodyne");
  msg.height = 1;
  msg.width = 2;
  msg.fields = {{"x", 0, RosPointField::FLOAT32, 1},
                {"y", 4, RosPointField::FLOAT32, 1},
                {"z", 8, RosPointField::FLOAT32, 1},
                {"intensity", 12, RosPointField::UINT8, 1}};
  msg.is_bigendian = false;
  msg.point_step = 13;
  msg.row_step = 26;
  const float xyz[2][3] = {{1.5f, -2.0f, 0.25f}, {3.0f, 4.0f, -5.0f}};
  msg.data.assign(26, 0);
  for (int i = 0; i < 2; ++i) {
    std::memcpy(&msg.data[13 * i], xyz[i], 12);
    msg.data[13 * i + 12] = static_cast<uint8_t>(40 + i);
  }
  msg.is_dense = true;
  return msg;
}

RosImage SampleImage() {
  RosImage msg;
  msg.header = Header("camera_optical");
  msg.height = 2;
  msg.width = 3;
  msg.encoding = "rgb8";
  msg.step = 10;  // one byte of padding per row
  for (int i = 0; i < 20; ++i) msg.data.push_back(static_cast<uint8_t>(i * 7));
  return msg;
}

RosCompressedImage SampleCompressed() {
  RosCompressedImage msg;
  msg.header = Header("camera_optical");
  msg.format = "bgr8; jpeg compressed bgr8";
  msg.data = {0xFF, 0xD8, 0xFF, 0xE0, 1, 2, 3};
  return msg;
}

RosCameraInfo SampleCameraInfo() {
  RosCameraInfo msg;
  msg.header = Header("camera_optical");
  msg.height = 480;
  msg.width = 640;
  msg.distortion_model = "plumb_bob";
  msg.D = {-0.2, 0.05, 0.001, -0.002, 0.0};
  msg.K = {400, 0, 319.5, 0, 401, 239.5, 0, 0, 1};
  msg.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  msg.P = {400, 0, 319.5, 0, 0, 401, 239.5, 0, 0, 0, 1, 0};
  msg.binning_x = 1;
  msg.binning_y = 2;
  msg.roi = RosRegionOfInterest{3, 4, 5, 6, true};
  return msg;
}

void ExpectSameHeader(const RosHeader& a, const RosHeader& b) {
  EXPECT_EQ(a.stamp.sec, b.stamp.sec);
  EXPECT_EQ(a.stamp.nsec, b.stamp.nsec);
  EXPECT_EQ(a.frame_id, b.frame_id);
}

void ExpectSame(const RosPointCloud2& a, const RosPointCloud2& b) {
  ExpectSameHeader(a.header, b.header);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.width, b.width);
  ASSERT_EQ(a.fields.size(), b.fields.size());
  for (size_t i = 0; i < a.fields.size(); ++i) {
    EXPECT_EQ(a.fields[i].name, b.fields[i].name);
    EXPECT_EQ(a.fields[i].offset, b.fields[i].offset);
    EXPECT_EQ(a.fields[i].datatype, b.fields[i].datatype);
    EXPECT_EQ(a.fields[i].count, b.fields[i].count);
  }
  EXPECT_EQ(a.is_bigendian, b.is_bigendian);
  EXPECT_EQ(a.point_step, b.point_step);
  EXPECT_EQ(a.row_step, b.row_step);
  EXPECT_EQ(a.data, b.data);
  EXPECT_EQ(a.is_dense, b.is_dense);
}

void ExpectSame(const RosImage& a, const RosImage& b) {
  ExpectSameHeader(a.header, b.header);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.encoding, b.encoding);
  EXPECT_EQ(a.is_bigendian, b.is_bigendian);
  EXPECT_EQ(a.step, b.step);
  EXPECT_EQ(a.data, b.data);
}

void ExpectSame(const RosCompressedImage& a, const RosCompressedImage& b) {
  ExpectSameHeader(a.header, b.header);
  EXPECT_EQ(a.format, b.format);
  EXPECT_EQ(a.data, b.data);
}

void ExpectSame(const RosCameraInfo& a, const RosCameraInfo& b) {
  ExpectSameHeader(a.header, b.header);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.distortion_model, b.distortion_model);
  EXPECT_EQ(a.D, b.D);
  EXPECT_EQ(a.K, b.K);
  EXPECT_EQ(a.R, b.R);
  EXPECT_EQ(a.P, b.P);
  EXPECT_EQ(a.binning_x, b.binning_x);
  EXPECT_EQ(a.binning_y, b.binning_y);
  EXPECT_EQ(a.roi.x_offset, b.roi.x_offset);
  EXPECT_EQ(a.roi.y_offset, b.roi.y_offset);
  EXPECT_EQ(a.roi.height, b.roi.height);
  EXPECT_EQ(a.roi.width, b.roi.width);
  EXPECT_EQ(a.roi.do_rectify, b.roi.do_rectify);
}

// The message of the std::runtime_error `decode` throws; a failure when it throws nothing.
std::string ErrorOf(const std::function<void()>& decode) {
  try {
    decode();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "decoded without an error";
  return "";
}

TEST(RosCdr, EachMessageRoundTripsInBothByteOrders) {
  for (const CdrByteOrder order : kOrders) {
    SCOPED_TRACE(order == CdrByteOrder::kBig ? "big-endian" : "little-endian");
    const Bytes cloud = EncodeCdr(SampleCloud(), order);
    EXPECT_EQ(cloud[1], order == CdrByteOrder::kBig ? 0x00 : 0x01);
    ExpectSame(DecodeCdrPointCloud2(cloud.data(), cloud.size()), SampleCloud());
    const Bytes image = EncodeCdr(SampleImage(), order);
    ExpectSame(DecodeCdrImage(image.data(), image.size()), SampleImage());
    const Bytes compressed = EncodeCdr(SampleCompressed(), order);
    ExpectSame(DecodeCdrCompressedImage(compressed.data(), compressed.size()), SampleCompressed());
    const Bytes info = EncodeCdr(SampleCameraInfo(), order);
    ExpectSame(DecodeCdrCameraInfo(info.data(), info.size()), SampleCameraInfo());
  }
  // Empty strings and sequences, and a negative ROS 2 stamp (int32 seconds).
  RosCameraInfo empty;
  empty.header.stamp = RosTime{-5, 7};
  const Bytes bytes = EncodeCdr(empty, CdrByteOrder::kBig);
  ExpectSame(DecodeCdrCameraInfo(bytes.data(), bytes.size()), empty);
}

TEST(RosCdr, BytesAfterTheMessageAreIgnored) {
  Bytes image = EncodeCdr(SampleImage());
  image.insert(image.end(), {0, 0, 0});  // padding to a multiple of 4, as DDS sends it
  ExpectSame(DecodeCdrImage(image.data(), image.size()), SampleImage());
}

// A 2 x 1 mono8 Image, little-endian, laid out by hand. Offsets count from the end of the 4-byte
// encapsulation header; each field is aligned to its size from there.
const Bytes kGoldenImageLittle = {
    0x00, 0x01, 0x00, 0x00,             // encapsulation: CDR_LE, options 0
    0x01, 0x00, 0x00, 0x00,             //  0: header.stamp.sec = 1 (int32)
    0x02, 0x00, 0x00, 0x00,             //  4: header.stamp.nanosec = 2
    0x04, 0x00, 0x00, 0x00,             //  8: header.frame_id length 4 (with the NUL)
    'c',  'a',  'm',  0x00,             // 12: "cam\0"
    0x01, 0x00, 0x00, 0x00,             // 16: height = 1
    0x02, 0x00, 0x00, 0x00,             // 20: width = 2
    0x06, 0x00, 0x00, 0x00,             // 24: encoding length 6
    'm',  'o',  'n',  'o',  '8', 0x00,  // 28: "mono8\0"
    0x00,                               // 34: is_bigendian = 0 (uint8)
    0x00,                               // 35: padding: step is a uint32, at 36
    0x02, 0x00, 0x00, 0x00,             // 36: step = 2
    0x02, 0x00, 0x00, 0x00,             // 40: data count 2
    0x07, 0x09,                         // 44: data
};

// The same Image big-endian: the integers' bytes turn round, nothing moves.
const Bytes kGoldenImageBig = {
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x04, 'c',
    'a',  'm',  0x00, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x06, 'm',  'o',
    'n',  'o',  '8',  0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x02, 0x07, 0x09,
};

RosImage GoldenImage() {
  RosImage msg;
  msg.header = RosHeader{RosTime{1, 2}, "cam"};
  msg.height = 1;
  msg.width = 2;
  msg.encoding = "mono8";
  msg.step = 2;
  msg.data = {7, 9};
  return msg;
}

TEST(RosCdr, AGoldenImageLaidOutByHandDecodesAndIsWhatTheWriterWrites) {
  ExpectSame(DecodeCdrImage(kGoldenImageLittle.data(), kGoldenImageLittle.size()), GoldenImage());
  ExpectSame(DecodeCdrImage(kGoldenImageBig.data(), kGoldenImageBig.size()), GoldenImage());
  EXPECT_EQ(EncodeCdr(GoldenImage(), CdrByteOrder::kLittle), kGoldenImageLittle);
  EXPECT_EQ(EncodeCdr(GoldenImage(), CdrByteOrder::kBig), kGoldenImageBig);
  SixteenBitScaler scaler;
  const cv::Mat pixels = RosImageToMat(DecodeCdrImage(kGoldenImageLittle.data(), kGoldenImageLittle.size()), scaler);
  ASSERT_EQ(pixels.type(), CV_8UC1);
  EXPECT_EQ(pixels.at<uint8_t>(0, 1), 9);
}

// Little-endian values appended with no alignment logic: the padding is written out by hand below.
struct HandLayout {
  Bytes bytes{0x00, 0x01, 0x00, 0x00};
  void U32(uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  void F64(double v) {
    uint64_t bits;
    std::memcpy(&bits, &v, 8);
    for (int i = 0; i < 8; ++i) bytes.push_back(static_cast<uint8_t>(bits >> (8 * i)));
  }
  void Raw(std::initializer_list<uint8_t> raw) { bytes.insert(bytes.end(), raw); }
  void Pad(int n) { bytes.insert(bytes.end(), static_cast<size_t>(n), 0); }
};

// A CameraInfo whose float64s sit at 8-byte boundaries counted from the end of the encapsulation header,
// not from the start of the buffer: the two differ by 4 here.
TEST(RosCdr, AGoldenCameraInfoAlignsItsDoublesFromTheEndOfTheEncapsulationHeader) {
  RosCameraInfo expected;
  expected.header = RosHeader{RosTime{3, 4}, ""};
  expected.height = 2;
  expected.width = 3;
  expected.distortion_model = "plumb_bob";
  expected.D = {0.5};
  for (int i = 0; i < 9; ++i) expected.K[i] = i + 1;
  expected.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  for (int i = 0; i < 12; ++i) expected.P[i] = 0.25 * i;
  HandLayout in;
  in.U32(3);                                                    //  0: header.stamp.sec
  in.U32(4);                                                    //  4: header.stamp.nanosec
  in.U32(1);                                                    //  8: header.frame_id length 1: ""
  in.Raw({0x00});                                               // 12: its NUL
  in.Pad(3);                                                    // 13: height is a uint32, at 16
  in.U32(2);                                                    // 16: height
  in.U32(3);                                                    // 20: width
  in.U32(10);                                                   // 24: distortion_model length 10
  in.Raw({'p', 'l', 'u', 'm', 'b', '_', 'b', 'o', 'b', 0x00});  // 28
  in.Pad(2);                                                    // 38: the count of d is a uint32, at 40
  in.U32(1);                                                    // 40: d count 1
  in.Pad(4);                              // 44: d[0] is a float64, at 48 (52 from the buffer's start)
  in.F64(0.5);                            // 48: d[0]
  for (double k : expected.K) in.F64(k);  // 56: k
  for (double r : expected.R) in.F64(r);  // 128: r
  for (double p : expected.P) in.F64(p);  // 200: p
  in.U32(0);                              // 296: binning_x
  in.U32(0);                              // 300: binning_y
  for (int i = 0; i < 4; ++i) in.U32(0);  // 304: roi x_offset, y_offset, height, width
  in.Raw({0x00});                         // 320: roi.do_rectify
  ASSERT_EQ(in.bytes.size(), 4u + 321u);
  ExpectSame(DecodeCdrCameraInfo(in.bytes.data(), in.bytes.size()), expected);
  EXPECT_EQ(EncodeCdr(expected), in.bytes);
}

// Each message cut short at every length before its end: an error naming the type and, past the
// encapsulation header, the field and the offset.
template <typename Message, typename Decode>
void ExpectEveryTruncationRefused(const Message& msg, Decode decode, const std::string& type) {
  for (const CdrByteOrder order : kOrders) {
    const Bytes bytes = EncodeCdr(msg, order);
    for (size_t n = 0; n < bytes.size(); ++n) {
      SCOPED_TRACE(type + " cut to " + std::to_string(n) + " bytes");
      const Bytes cut(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n));
      const std::string error = ErrorOf([&] { decode(cut.data(), cut.size()); });
      EXPECT_EQ(error.rfind(type + ": ", 0), 0u) << error;
      if (n >= 4) {
        EXPECT_NE(error.find("field '"), std::string::npos) << error;
        EXPECT_NE(error.find("the " + std::to_string(n) + "-byte message at offset "), std::string::npos) << error;
      }
    }
  }
}

TEST(RosCdr, AMessageCutShortAnywhereIsRefusedNamingTheField) {
  ExpectEveryTruncationRefused(SampleCloud(), DecodeCdrPointCloud2, "sensor_msgs/msg/PointCloud2");
  ExpectEveryTruncationRefused(SampleImage(), DecodeCdrImage, "sensor_msgs/msg/Image");
  ExpectEveryTruncationRefused(SampleCompressed(), DecodeCdrCompressedImage, "sensor_msgs/msg/CompressedImage");
  ExpectEveryTruncationRefused(SampleCameraInfo(), DecodeCdrCameraInfo, "sensor_msgs/msg/CameraInfo");
  // Offsets count from the start of the bytes: step (body offset 36) is at 40.
  const std::string error = ErrorOf([] { DecodeCdrImage(kGoldenImageLittle.data(), 41); });
  EXPECT_EQ(error,
            "sensor_msgs/msg/Image: field 'step' (4 bytes) runs past the end of the 41-byte message at offset 40");
}

void PutU32(Bytes& bytes, size_t at, uint32_t value) {
  for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<uint8_t>(value >> (8 * i));
}

TEST(RosCdr, LengthsThatLieAreRefusedBeforeAnythingIsAllocated) {
  Bytes image = kGoldenImageLittle;
  PutU32(image, 28, 0xFFFFFFFFu);  // encoding length
  EXPECT_EQ(ErrorOf([&] { DecodeCdrImage(image.data(), image.size()); }),
            "sensor_msgs/msg/Image: field 'encoding' length 4294967295 runs past the end of the 50-byte message "
            "at offset 28");
  image = kGoldenImageLittle;
  PutU32(image, 12, 35);  // frame_id length: one byte more than the rest of the message
  EXPECT_NE(ErrorOf([&] { DecodeCdrImage(image.data(), image.size()); }).find("field 'header.frame_id' length 35"),
            std::string::npos);
  image = kGoldenImageLittle;
  PutU32(image, 44, 3);  // data count 3, two bytes follow
  EXPECT_NE(ErrorOf([&] { DecodeCdrImage(image.data(), image.size()); }).find("field 'data' length 3"),
            std::string::npos);

  Bytes cloud = EncodeCdr(SampleCloud());
  const size_t data_count_at = cloud.size() - 1 - SampleCloud().data.size() - 4;
  PutU32(cloud, data_count_at, 0xFFFFFFFFu);
  EXPECT_EQ(ErrorOf([&] { DecodeCdrPointCloud2(cloud.data(), cloud.size()); }),
            "sensor_msgs/msg/PointCloud2: field 'data' length 4294967295 runs past the end of the " +
                std::to_string(cloud.size()) + "-byte message at offset " + std::to_string(data_count_at));
  cloud = EncodeCdr(SampleCloud());
  const size_t fields_count_at = 4 + 8 + 4 + 12 + 8;  // after the stamp, "velodyne\0" (+3), height, width
  PutU32(cloud, fields_count_at, 1000000000u);
  EXPECT_NE(ErrorOf([&] {
              DecodeCdrPointCloud2(cloud.data(), cloud.size());
            }).find("field 'fields' length 1000000000 runs past the end"),
            std::string::npos);

  // 2^29 float64s are 2^32 bytes: 0 in 32 bits, refused in 64.
  Bytes info = EncodeCdr(SampleCameraInfo());
  const size_t d_count_at = 4 + 8 + 4 + 16 + 8 + 4 + 10 + 2;  // stamp, "camera_optical\0" (+1), sizes, model
  ASSERT_EQ(info[d_count_at], 5);
  PutU32(info, d_count_at, 1u << 29);
  EXPECT_NE(ErrorOf([&] { DecodeCdrCameraInfo(info.data(), info.size()); }).find("field 'd' length 536870912"),
            std::string::npos);
}

TEST(RosCdr, AnotherEncapsulationOrNoBytesAreRefusedByName) {
  Bytes cdr2 = kGoldenImageLittle;
  cdr2[1] = 0x07;
  EXPECT_EQ(ErrorOf([&] { DecodeCdrImage(cdr2.data(), cdr2.size()); }),
            "sensor_msgs/msg/Image: encapsulation 0x0007 (CDR2_LE) is not supported; plain CDR only "
            "(0x0000 CDR_BE, 0x0001 CDR_LE)");
  Bytes parameter_list = kGoldenImageLittle;
  parameter_list[1] = 0x03;
  EXPECT_NE(ErrorOf([&] { DecodeCdrImage(parameter_list.data(), parameter_list.size()); }).find("PL_CDR_LE"),
            std::string::npos);
  Bytes unknown = kGoldenImageLittle;
  unknown[0] = 0x7F;
  EXPECT_NE(ErrorOf([&] { DecodeCdrImage(unknown.data(), unknown.size()); }).find("encapsulation 0x7f01 is not"),
            std::string::npos);
  EXPECT_EQ(ErrorOf([] { DecodeCdrCameraInfo(nullptr, 0); }),
            "sensor_msgs/msg/CameraInfo: 0 bytes, shorter than the 4-byte encapsulation header");
}

// Every byte of each message set to 0xFF in turn: decoded and converted, or refused with a
// std::runtime_error; never a crash or another exception.
TEST(RosCdr, EveryByteCorruptedDecodesOrIsRefused) {
  SixteenBitScaler scaler;
  const auto attempt = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const std::runtime_error&) {
    }
  };
  const Bytes messages[] = {EncodeCdr(SampleCloud()), EncodeCdr(SampleImage(), CdrByteOrder::kBig),
                            EncodeCdr(SampleCameraInfo())};
  for (const Bytes& original : messages)
    for (size_t i = 0; i < original.size(); ++i) {
      Bytes bytes = original;
      bytes[i] = 0xFF;
      attempt([&] { RosCloudToPointCloud(DecodeCdrPointCloud2(bytes.data(), bytes.size())); });
      attempt([&] { RosImageToMat(DecodeCdrImage(bytes.data(), bytes.size()), scaler); });
      attempt([&] { RosCameraInfoToParams(DecodeCdrCameraInfo(bytes.data(), bytes.size())); });
    }
}

TEST(RosCdr, ADecodedCloudConverts) {
  const Bytes bytes = EncodeCdr(SampleCloud(), CdrByteOrder::kBig);
  int dropped = -1;
  const PointCloud cloud = RosCloudToPointCloud(DecodeCdrPointCloud2(bytes.data(), bytes.size()), &dropped);
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(dropped, 0);
  EXPECT_EQ(cloud.points[1], Eigen::Vector3f(3, 4, -5));
  EXPECT_EQ(cloud.intensity[0], 40.0f);
  EXPECT_EQ(RosStampToUtime(SampleCloud().header.stamp), 1700000000123456);
  // A uint16 ring that no int16 holds is refused, not converted (that would be undefined behaviour).
  RosPointCloud2 ring = SampleCloud();
  ring.fields.push_back({"ring", 10, RosPointField::UINT16, 1});  // the upper half of z: a field may overlap
  ring.data[10] = 0x00;
  ring.data[11] = 0x8B;  // ring 35584 in the first point, z still finite
  EXPECT_NE(ErrorOf([&] { RosCloudToPointCloud(ring); }).find("ring 35584.000000 is not a beam index"),
            std::string::npos);
}

}  // namespace
}  // namespace fusecal
