// What the fixes of the fuzzing findings promise, beyond "no crash" (test_fuzz_replay.cpp): each input
// that crashed is now a clear rejection, and valid input still decodes as before.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "fusecal/motion_set_t.hpp"
#include "fusecal/point_cloud_t.hpp"
#include "fusecal/status_t.hpp"
#include "fuzz_support.hpp"
#include "runtime/bus.hpp"
#include "runtime/io/importers/ishikawa.hpp"
#include "runtime/io/importers/kitti.hpp"
#include "runtime/io/scan_io/scan_io.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/image_header.hpp"

namespace fusecal {
namespace {

void PutBigEndian32(std::vector<uint8_t>* bytes, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) bytes->push_back(uint8_t(v >> shift));
}

// The fingerprint (8 bytes) and utime (8 bytes) every fusecal message starts with.
template <typename M>
std::vector<uint8_t> MessageStart() {
  std::vector<uint8_t> bytes;
  const uint64_t hash = static_cast<uint64_t>(M::getHash());
  PutBigEndian32(&bytes, uint32_t(hash >> 32));
  PutBigEndian32(&bytes, uint32_t(hash));
  bytes.resize(16, 0);
  return bytes;
}

template <typename M>
bool Decodes(const std::vector<uint8_t>& bytes) {
  M message;
  return message.decode(bytes.data(), 0, static_cast<int>(bytes.size())) >= 0;
}

TEST(HardenedLcmDecoders, ACountBeyondTheBytesIsCorruptNotAnAllocation) {
  std::vector<uint8_t> cloud = MessageStart<point_cloud_t>();
  PutBigEndian32(&cloud, 1);  // frame_id: "" (its NUL)
  cloud.push_back(0);
  PutBigEndian32(&cloud, 0x7fffffff);  // num_points: 8 GB of floats that are not there
  cloud.resize(cloud.size() + 64, 0);
  EXPECT_FALSE(Decodes<point_cloud_t>(cloud));
  point_cloud_t message;
  EXPECT_THROW(DecodeMessage(cloud.data(), cloud.size(), "LIDAR_SCAN", &message), BusError);

  std::vector<uint8_t> set = MessageStart<motion_set_t>();
  PutBigEndian32(&set, 1);           // extrinsic_version
  PutBigEndian32(&set, 0xa4b4b4b4);  // num_motions < 0
  EXPECT_FALSE(Decodes<motion_set_t>(set));
}

TEST(HardenedLcmDecoders, AStringLengthBelowOneIsCorrupt) {
  for (uint32_t length : {0u, 0xfffffffbu, 0x80000000u}) {
    std::vector<uint8_t> status = MessageStart<status_t>();
    PutBigEndian32(&status, length);  // name
    status.resize(status.size() + 32, 'x');
    EXPECT_FALSE(Decodes<status_t>(status)) << "length " << length;
  }
}

TEST(HardenedLcmDecoders, ValidMessagesDecodeAsBefore) {
  status_t s{};
  s.name = "handeye";
  s.state = "running";
  s.num_counters = 1;
  s.counter_names = {"stations"};
  s.counter_values = {4};
  std::vector<uint8_t> bytes(static_cast<size_t>(s.getEncodedSize()));
  ASSERT_GT(s.encode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  status_t back;
  ASSERT_EQ(back.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  EXPECT_EQ(back.counter_names, s.counter_names);
  EXPECT_EQ(back.name, "handeye");
}

// SOI, an SOF0 of `width` x `height` and nothing else: a few bytes that declare any size.
std::vector<uint8_t> JpegHeader(int width, int height) {
  return {0xff,
          0xd8,
          0xff,
          0xe0,
          0x00,
          0x04,
          0x00,
          0x00,
          0xff,
          0xc0,
          0x00,
          0x11,
          0x08,
          uint8_t(height >> 8),
          uint8_t(height),
          uint8_t(width >> 8),
          uint8_t(width),
          0x03};
}

TEST(CompressedImages, TheHeaderSizeIsReadWithoutDecoding) {
  const cv::Mat grey(37, 53, CV_8UC1, cv::Scalar(90));
  for (const char* encoding : {"jpeg", "png"}) {
    const image_t msg = MatToImage(grey, encoding, 0);
    const auto size = CompressedImageSize(msg.data, encoding);
    ASSERT_TRUE(size) << encoding;
    EXPECT_EQ(size->width, 53);
    EXPECT_EQ(size->height, 37);
    EXPECT_EQ(ImageToMat(msg).size(), grey.size());
  }
  const auto declared = CompressedImageSize(JpegHeader(60000, 40000), "jpeg");
  ASSERT_TRUE(declared);
  EXPECT_EQ(declared->width, 60000);
  EXPECT_FALSE(CompressedImageSize(JpegHeader(0, 10), "jpeg"));
}

TEST(CompressedImages, AHugeDeclaredSizeOrAnotherFormatIsRejected) {
  image_t msg{};
  msg.encoding = "jpeg";
  msg.data = JpegHeader(60000, 40000);
  try {
    ImageToMat(msg);
    FAIL() << "a 60000x40000 JPEG header was decoded";
  } catch (const ConversionError& e) {
    EXPECT_NE(std::string(e.what()).find("larger than 8192x8192"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ImageToMatReduced(msg, 64), ConversionError);
  msg = MatToImage(cv::Mat(8, 8, CV_8UC1, cv::Scalar(1)), "png", 0);
  msg.encoding = "jpeg";  // PNG bytes labelled jpeg: imdecode would decode any format it knows
  EXPECT_THROW(ImageToMat(msg), ConversionError);
}

TEST(RawImages, ASizeWhoseBytesOverflow64BitsIsRejected) {
  image_t msg{};
  msg.encoding = "bgr8";
  msg.width = 2000000000;
  msg.height = 2000000000;  // 3 x width x height bytes: more than 2^63
  msg.data.assign(16, 0);
  try {
    ImageToMat(msg);
    FAIL() << "a 2e9 x 2e9 image of 16 bytes was accepted";
  } catch (const ConversionError& e) {
    EXPECT_NE(std::string(e.what()).find("rows of 6000000000 bytes"), std::string::npos) << e.what();
  }
}

TEST(KittiTimestamps, OutOfRangeFieldsAreRejectedNotOverflowed) {
  EXPECT_EQ(ParseKittiTimestamp("1970-01-01 00:00:01.500000000"), 1500000);
  EXPECT_EQ(ParseKittiTimestamp("2011-09-26 13:02:25.964389445"), 1317042145964389);
  for (const char* bad : {"20200020-01-02 03:04:05.2202", "2020-13-02 03:04:05.1", "2020-01-02 24:00:00.0",
                          "2020-01-02 03:04:nan", "2020-01-02 03:04:1e300"}) {
    try {
      ParseKittiTimestamp(bad);
      FAIL() << "accepted '" << bad << "'";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("out of range"), std::string::npos) << e.what();
    }
  }
}

std::vector<std::filesystem::path> Seeds(const std::string& target) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(FUZZ_CORPUS_DIR) + "/" + target))
    files.push_back(entry.path());
  return files;
}

std::string ScanFile(const std::string& name, const std::string& text) {
  return fuzz::WriteScratchFile(name, reinterpret_cast<const uint8_t*>(text.data()), text.size());
}

TEST(ScanFiles, TheSeedScansStillRead) {
  for (const char* target : {"scan_pcd", "scan_ply"})
    for (const auto& seed : Seeds(target)) {
      const std::string copy = std::filesystem::path(fuzz::ScratchFolder()) / ("seed" + seed.extension().string());
      std::filesystem::copy_file(seed, copy, std::filesystem::copy_options::overwrite_existing);
      EXPECT_GE(ReadScan(copy).size(), 3u) << seed;
    }
  for (const auto& seed : Seeds("ply_with_pose")) EXPECT_GE(ReadPlyWithPose(seed.string()).cloud.size(), 3u) << seed;
}

void ExpectRejected(const std::string& path, const std::string& words) {
  try {
    ReadScan(path);
    FAIL() << path << " was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

const char* kPcdHead = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";

TEST(ScanFiles, PcdHeadersThatPclWouldTrustAreRejected) {
  ExpectRejected(ScanFile("wide.pcd", std::string(kPcdHead) + "WIDTH 4294967296\nHEIGHT 4294967296\nDATA binary\n"),
                 "bad WIDTH");
  ExpectRejected(ScanFile("after.pcd", std::string(kPcdHead) + "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA binary\n" +
                                           "POINTS 99999999999\n" + std::string(12, '\0')),
                 "PCL would read as a header line");
  std::string compressed = std::string(kPcdHead) + "WIDTH 100000000\nHEIGHT 1\nDATA binary_compressed\n";
  const uint32_t sizes[2] = {4, 1200000000u};  // 4 bytes of LZF for 1.2 GB
  compressed.append(reinterpret_cast<const char*>(sizes), 8).append(4, '\0');
  ExpectRejected(ScanFile("lzf.pcd", compressed), "LZF expands at most");
}

TEST(ScanFiles, PlyHeadersThatPclWouldTrustAreRejected) {
  const std::string head = "ply\nformat binary_little_endian 1.0\n";
  ExpectRejected(
      ScanFile("list.ply", head + "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n" +
                               "property list uchar int extra\nend_header\n" + std::string(32, '\0')),
      "list property in the vertex element");
  ExpectRejected(ScanFile("many.ply", head + "element vertex 1000000000\nproperty float x\nproperty float y\n" +
                                          "property float z\nend_header\n" + std::string(24, '\0')),
                 "declares 1000000000 instances");
}

TEST(PlyWithPose, ADeclaredVertexCountIsNotAllocatedBeforeTheDataIsThere) {
  const std::string path = ScanFile("posed.ply",
                                    "ply\nformat ascii 1.0\nelement vertex 66666666666666\n"
                                    "property float x\nproperty float y\nproperty float z\n"
                                    "end_header\n1 2 3\n");
  EXPECT_THROW(ReadPlyWithPose(path), std::runtime_error);
}

}  // namespace
}  // namespace fusecal
