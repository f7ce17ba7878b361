// Scan files: KITTI .bin, .pcd, .ply round trips, and clear errors on missing, truncated, corrupt files.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>

#include "runtime/io/scan_io/scan_io.hpp"

namespace fusecal {
namespace {

namespace fs = std::filesystem;

class ScanIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("fusecal_scan_io_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  static PointCloud Sample(bool all_fields) {
    PointCloud c;
    for (int i = 0; i < 50; ++i) {
      c.points.emplace_back(0.5f * i, -1.25f * i, 0.01f * i * i);
      if (all_fields) {
        c.intensity.push_back(0.02f * i);
        c.ring.push_back(static_cast<int16_t>(i % 64));
        c.time_offset_s.push_back(1e-3f * i);
      }
    }
    c.points[7] = Eigen::Vector3f(std::numeric_limits<float>::quiet_NaN(), 1.0f, 2.0f);  // kept
    return c;
  }

  static void ExpectSame(const PointCloud& a, const PointCloud& b) {
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        if (std::isnan(a.points[i][k])) {
          EXPECT_TRUE(std::isnan(b.points[i][k])) << i;
        } else {
          EXPECT_EQ(a.points[i][k], b.points[i][k]) << i;
        }
      }
    EXPECT_EQ(a.intensity, b.intensity);
    EXPECT_EQ(a.ring, b.ring);
    EXPECT_EQ(a.time_offset_s, b.time_offset_s);
  }

  static void ExpectThrowNaming(const std::string& path, const std::string& what) {
    try {
      ReadScan(path);
      FAIL() << "no exception for " << path;
    } catch (const std::runtime_error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path), std::string::npos) << message;
      EXPECT_NE(message.find(what), std::string::npos) << message;
    }
  }

  fs::path dir_;
};

TEST_F(ScanIo, PcdAndPlyRoundTripAllFieldsAndKeepNaN) {
  const PointCloud c = Sample(true);
  for (const char* name : {"scan.pcd", "scan.ply", "SCAN.PCD"}) {
    WriteScan(Path(name), c);
    ExpectSame(c, ReadScan(Path(name)));
  }
}

TEST_F(ScanIo, PcdAndPlyWithOnlyXyz) {
  const PointCloud c = Sample(false);
  for (const char* name : {"xyz.pcd", "xyz.ply"}) {
    WriteScan(Path(name), c);
    ExpectSame(c, ReadScan(Path(name)));
  }
}

TEST_F(ScanIo, KittiBinRoundTrip) {
  PointCloud c = Sample(true);
  WriteScan(Path("scan.bin"), c);
  EXPECT_EQ(fs::file_size(Path("scan.bin")), 16 * c.size());
  const PointCloud back = ReadScan(Path("scan.bin"));
  c.ring.clear();  // .bin holds x y z reflectance only
  c.time_offset_s.clear();
  ExpectSame(c, back);
}

TEST_F(ScanIo, AsciiPcdWrittenByHand) {
  std::ofstream(Path("ascii.pcd")) << "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity ring\nSIZE 4 4 4 4 2\n"
                                      "TYPE F F F F U\nCOUNT 1 1 1 1 1\nWIDTH 2\nHEIGHT 1\n"
                                      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA ascii\n"
                                      "1 2 3 0.5 7\nnan 5 6 0.25 8\n";
  const PointCloud c = ReadScan(Path("ascii.pcd"));
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.points[0], Eigen::Vector3f(1, 2, 3));
  EXPECT_TRUE(std::isnan(c.points[1].x()));
  EXPECT_EQ(c.intensity[1], 0.25f);
  EXPECT_EQ(c.ring[1], 8);
  EXPECT_TRUE(c.time_offset_s.empty());
}

TEST_F(ScanIo, MissingFileThrowsNamingIt) {
  for (const char* name : {"missing.bin", "missing.pcd", "missing.ply"})
    ExpectThrowNaming(Path(name), "does not exist");
}

TEST_F(ScanIo, TruncatedBinThrows) {
  WriteScan(Path("t.bin"), Sample(true));
  fs::resize_file(Path("t.bin"), 16 * 10 + 5);
  ExpectThrowNaming(Path("t.bin"), "not a multiple of 16");
}

TEST_F(ScanIo, TruncatedPcdAndPlyThrow) {
  for (const char* name : {"t.pcd", "t.ply"}) {
    WriteScan(Path(name), Sample(true));
    fs::resize_file(Path(name), fs::file_size(Path(name)) - 100);
    ExpectThrowNaming(Path(name), "");
  }
}

TEST_F(ScanIo, TruncatedAsciiPcdThrows) {
  const std::string header =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\n"
      "POINTS 3\nDATA ascii\n";
  std::ofstream(Path("short_line.pcd")) << header << "1 2 3\n4 5 6\n7 8\n";
  std::ofstream(Path("short_file.pcd")) << header << "1 2 3\n4 5 6\n";
  ExpectThrowNaming(Path("short_line.pcd"), "point 3 has 2 values");
  ExpectThrowNaming(Path("short_file.pcd"), "2 of 3 points");
}

TEST_F(ScanIo, CorruptHeadersThrow) {
  std::ofstream(Path("bad.pcd")) << "this is not a point cloud\n";
  std::ofstream(Path("bad.ply")) << "ply\nformat nonsense 9.9\nend_header\n";
  ExpectThrowNaming(Path("bad.pcd"), "");
  ExpectThrowNaming(Path("bad.ply"), "");
}

TEST_F(ScanIo, UnsupportedExtensionThrows) {
  std::ofstream(Path("scan.xyz")) << "1 2 3\n";
  ExpectThrowNaming(Path("scan.xyz"), "unsupported extension");
  EXPECT_THROW(WriteScan(Path("out.las"), Sample(false)), std::runtime_error);
}

TEST_F(ScanIo, EmptyBinIsAnEmptyScan) {
  std::ofstream(Path("empty.bin")).close();
  EXPECT_TRUE(ReadScan(Path("empty.bin")).empty());
}

}  // namespace
}  // namespace fusecal
