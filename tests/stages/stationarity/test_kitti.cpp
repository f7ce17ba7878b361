// Real data: the KITTI raw snippet (a car driving, decelerating from about frame 40 and nearly stopped
// from about frame 54 to 76), fed as two streams at their timestamps. The default settings must emit no
// station while the car drives and exactly one for the stop at the end. Skipped when the data is absent.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "runtime/io/scan_io/scan_io.hpp"
#include "stages/stationarity/stationarity_detector.hpp"

namespace fusecal {
namespace {

namespace fs = std::filesystem;

// "2011-09-26 13:00:00.200000000" -> microseconds since midnight (the snippet spans seconds, and the
// timestamps are nominal: frame index x 0.1 s).
int64_t ParseTimeOfDay(const std::string& line) {
  int h = 0, m = 0;
  double s = 0;
  const auto space = line.find(' ');
  if (space == std::string::npos || std::sscanf(line.c_str() + space + 1, "%d:%d:%lf", &h, &m, &s) != 3)
    throw std::runtime_error("bad KITTI timestamp: " + line);
  return (static_cast<int64_t>(h) * 3600 + m * 60) * 1000000 + std::llround(s * 1e6);
}

std::vector<int64_t> ReadTimestamps(const fs::path& file) {
  std::ifstream in(file);
  std::vector<int64_t> out;
  std::string line;
  while (std::getline(in, line))
    if (!line.empty()) out.push_back(ParseTimeOfDay(line));
  return out;
}

struct KittiFrame {
  int index = 0;  // KITTI frame number (file name)
  int64_t utime = 0;
  cv::Mat image;
  PointCloud cloud;
};

class KittiStationarity : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const fs::path dir(KITTI_SNIPPET_DIR);
    if (!fs::exists(dir / "image_02" / "data")) return;
    std::vector<fs::path> images, scans;
    for (const auto& e : fs::directory_iterator(dir / "image_02" / "data")) images.push_back(e.path());
    for (const auto& e : fs::directory_iterator(dir / "velodyne_points" / "data")) scans.push_back(e.path());
    std::sort(images.begin(), images.end());
    std::sort(scans.begin(), scans.end());
    const auto image_times = ReadTimestamps(dir / "image_02" / "timestamps.txt");
    const auto scan_times = ReadTimestamps(dir / "velodyne_points" / "timestamps.txt");
    ASSERT_EQ(images.size(), image_times.size());
    ASSERT_EQ(scans.size(), scan_times.size());
    ASSERT_EQ(images.size(), scans.size());
    frames_ = new std::vector<KittiFrame>();
    for (size_t i = 0; i < images.size(); ++i) {
      KittiFrame f;
      f.index = std::stoi(images[i].stem().string());
      ASSERT_EQ(f.index, std::stoi(scans[i].stem().string()));
      ASSERT_EQ(image_times[i], scan_times[i]);
      f.utime = image_times[i];
      f.image = cv::imread(images[i].string(), cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(f.image.empty()) << images[i];
      f.cloud = ReadScan(scans[i].string());
      frames_->push_back(std::move(f));
    }
  }
  static void TearDownTestSuite() {
    delete frames_;
    frames_ = nullptr;
  }
  void SetUp() override {
    if (!frames_) GTEST_SKIP() << "KITTI snippet not found at " << KITTI_SNIPPET_DIR;
  }

  // Streams image and scan of each frame (same timestamp; the scan first, as its sweep starts earlier),
  // returns the stations with the frame index that emitted them.
  static std::vector<std::pair<int, DetectedStation>> Run(StationarityDetector* detector, bool trace) {
    std::vector<std::pair<int, DetectedStation>> out;
    for (const KittiFrame& f : *frames_) {
      for (auto& s : detector->AddScan(f.utime, f.cloud)) out.emplace_back(f.index, std::move(s));
      for (auto& s : detector->AddImage(f.utime, f.image)) out.emplace_back(f.index, std::move(s));
      if (trace) {
        const StationarityState st = detector->State();
        std::printf("frame %2d %-8s flow %.3f drift %.3f change %.4f ldrift %.4f still %.2f s  %s\n", f.index,
                    ToString(st.phase), st.image_flow_px, st.image_drift_px, st.lidar_change_m, st.lidar_drift_m,
                    st.still_for_s, st.reason.c_str());
      }
    }
    if (auto s = detector->Flush()) out.emplace_back(frames_->back().index, std::move(*s));
    return out;
  }

  static int FrameOf(int64_t utime) {
    for (const auto& f : *frames_)
      if (f.utime == utime) return f.index;
    return -1;
  }

  static std::vector<KittiFrame>* frames_;
};

std::vector<KittiFrame>* KittiStationarity::frames_ = nullptr;

TEST_F(KittiStationarity, DefaultSettingsGiveOneStationForTheStopAndNoneWhileDriving) {
  StationarityDetector detector{StationaritySettings()};
  const auto stations = Run(&detector, std::getenv("FUSECAL_TRACE") != nullptr);
  ASSERT_EQ(stations.size(), 1u) << "expected exactly one station (the stop at the end)";
  const DetectedStation& s = stations[0].second;
  const int image_frame = FrameOf(s.image_utime), scan_frame = FrameOf(s.scan_utime);
  const int from_frame = FrameOf(s.still_from);
  std::cout << "station " << s.id << ": image frame " << image_frame << ", scan frame " << scan_frame
            << ", still from frame " << from_frame << ", emitted at frame " << stations[0].first << ", drift "
            << s.image_drift_px << " px, lidar change " << s.lidar_change_m << " m\n";
  EXPECT_EQ(s.id, 0);
  // Not while driving (0-40) nor decelerating; inside the stop (54-76).
  EXPECT_GE(from_frame, 54);
  EXPECT_GE(image_frame, 54);
  EXPECT_GE(scan_frame, 54);
  EXPECT_LE(s.utime, frames_->back().utime);
  EXPECT_EQ(s.image_utime, s.scan_utime);  // KITTI sync data: the closest pair is simultaneous
  EXPECT_EQ(s.utime, s.image_utime);
  EXPECT_EQ(s.image.size(), cv::Size(1242, 375));
  EXPECT_GT(s.cloud.size(), 100000u);
  // Emitted once still for min_still_s (frames are 0.2 s apart), not only at the end of the stream.
  EXPECT_LE(stations[0].first, FrameOf(s.still_from + 1'000'000) + 2);
  const StationarityState st = detector.State();
  EXPECT_EQ(st.counters.stations_emitted, 1);
  EXPECT_EQ(st.counters.images_used, static_cast<int64_t>(frames_->size()));
  EXPECT_EQ(st.counters.scans_used, static_cast<int64_t>(frames_->size()));
}

TEST_F(KittiStationarity, DrivingPartAloneGivesNoStation) {
  // Frames 0-40 only: the car drives, no station, and the state says moving with the image flow as reason.
  StationarityDetector detector{StationaritySettings()};
  for (const KittiFrame& f : *frames_) {
    if (f.index > 40) break;
    EXPECT_TRUE(detector.AddScan(f.utime, f.cloud).empty()) << "frame " << f.index;
    EXPECT_TRUE(detector.AddImage(f.utime, f.image).empty()) << "frame " << f.index;
    if (f.index > 0) {
      const StationarityState st = detector.State();
      EXPECT_EQ(st.phase, StationarityPhase::kMoving) << "frame " << f.index;
      EXPECT_FALSE(st.image_still) << "frame " << f.index << ": flow " << st.image_flow_px;
      EXPECT_GT(st.image_flow_px, 5 * detector.settings().image.still_flow_px) << "frame " << f.index;
    }
  }
  EXPECT_FALSE(detector.Flush().has_value());
}

TEST_F(KittiStationarity, LastFramesStandStill) {
  // The measures themselves during the stop (frames 62-76): far below the thresholds.
  StationarityDetector detector{StationaritySettings()};
  for (const KittiFrame& f : *frames_) {
    detector.AddScan(f.utime, f.cloud);
    detector.AddImage(f.utime, f.image);
    if (f.index < 62) continue;
    const StationarityState st = detector.State();
    EXPECT_TRUE(st.image_still) << "frame " << f.index << ": " << st.reason;
    EXPECT_TRUE(st.lidar_still) << "frame " << f.index << ": " << st.reason;
    EXPECT_LT(st.image_flow_px, 0.1) << "frame " << f.index;
    EXPECT_LT(st.lidar_change_m, 0.015) << "frame " << f.index;
  }
}

}  // namespace
}  // namespace fusecal
