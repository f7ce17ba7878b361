// Non-repetitive LiDARs (the simulator's rosette and petal models of the handheld scenarios): their "lines"
// are not beams, the LiDAR change is measured on patches of irregular points, every still interval gives
// one station, and the station cloud accumulates the still scans of accumulate_s seconds.
#include <gtest/gtest.h>

#include "runtime/sim/fixtures/stationarity_test_util.hpp"
#include "stages/stationarity/range_image.hpp"

namespace fusecal {
namespace {

using namespace fixtures;

// A handheld scenario made short (2 turns, 2 tilts) and its camera small (640 x 360) for the test's time.
const Recording& HandheldRecording(const std::string& file) {
  static std::map<std::string, Recording> recordings;
  auto it = recordings.find(file);
  if (it != recordings.end()) return it->second;
  sim::Scenario s = sim::LoadScenario(ScenarioPath(file));
  s.motions.horizontal = 2;
  s.motions.vertical = 2;
  CameraParams& c = s.camera().params;
  c.width /= 2;
  c.height /= 2;
  c.fx /= 2;
  c.fy /= 2;
  c.cx = (c.cx + 0.5) / 2 - 0.5;
  c.cy = (c.cy + 0.5) / 2 - 0.5;
  return recordings.emplace(file, Record(s)).first->second;
}

const PointCloud& FirstScan(const Recording& r) {
  for (const Frame& f : r.frames)
    if (!f.camera) return f.cloud;
  throw std::runtime_error("no scan");
}

TEST(NonRepetitiveLidar, LinesAreNotBeams) {
  const LidarChangeSettings settings;
  EXPECT_FALSE(RingsAreBeams(FirstScan(HandheldRecording("handheld-avia-pinhole.yaml")), settings));
  EXPECT_FALSE(RingsAreBeams(FirstScan(HandheldRecording("handheld-mid360-pinhole.yaml")), settings));
  EXPECT_TRUE(RingsAreBeams(FirstScan(TinyRecording()), settings));
  const RangeImage image = BuildRangeImage(FirstScan(HandheldRecording("handheld-avia-pinhole.yaml")), settings);
  EXPECT_FALSE(image.by_ring);
}

// Consecutive still scans sample other directions, with 2 cm of range noise: their change stays well below
// still_change_m.
TEST(NonRepetitiveLidar, StillScansChangeLessThanTheThreshold) {
  const Recording& r = HandheldRecording("handheld-mid360-pinhole.yaml");
  const LidarChangeSettings settings;
  const PointCloud* previous = nullptr;
  int compared = 0;
  for (const Frame& f : r.frames) {
    if (f.camera) continue;
    if (f.station_id < 0) {
      previous = nullptr;
      continue;
    }
    if (previous) {
      const LidarChange change =
          CompareRangeImages(BuildRangeImage(*previous, settings), BuildRangeImage(f.cloud, settings), settings);
      ASSERT_TRUE(change.usable()) << change.failure_reason.text;
      EXPECT_LT(change.change_m, 0.5 * settings.still_change_m);
      ++compared;
    }
    previous = &f.cloud;
  }
  EXPECT_GT(compared, 50);
}

void ExpectAccumulatedStations(const std::string& file) {
  SCOPED_TRACE(file);
  const Recording& r = HandheldRecording(file);
  const StationaritySettings settings;
  StationarityDetector detector(settings);
  const auto stations = Replay(r.frames, &detector);
  const Score score = ScoreStations(stations, r.truth, r.camera_station, r.scan_station, settings.min_still_s);
  EXPECT_EQ(score.true_intervals, 5);
  EXPECT_EQ(score.found, score.true_intervals);
  EXPECT_EQ(score.duplicates, 0);
  EXPECT_EQ(score.during_motion, 0);
  for (const auto& e : stations) {
    const DetectedStation& s = e.station;
    // 1 s of scans at 10 Hz, all of them still scans of the station's own interval.
    EXPECT_GE(s.merged_scan_utimes.size(), 10u);
    EXPECT_LE(s.merged_scan_utimes.size(), 11u);
    EXPECT_EQ(s.merged_scan_utimes.back(), s.scan_utime);
    for (int64_t utime : s.merged_scan_utimes) EXPECT_EQ(r.scan_station.at(utime), r.scan_station.at(s.scan_utime));
    EXPECT_GT(s.cloud.size(), 150000u);
    EXPECT_EQ(s.cloud.time_offset_s.size(), s.cloud.size());
  }
}

TEST(NonRepetitiveLidar, AviaLikeStationsAccumulateTheStillScans) {
  ExpectAccumulatedStations("handheld-avia-pinhole.yaml");
}

TEST(NonRepetitiveLidar, Mid360LikeStationsAccumulateTheStillScans) {
  ExpectAccumulatedStations("handheld-mid360-pinhole.yaml");
}

TEST(NonRepetitiveLidar, TheStationCloudKeepsToMaxStationPoints) {
  const Recording& r = HandheldRecording("handheld-avia-pinhole.yaml");
  StationaritySettings settings;
  settings.max_station_points = 50000;  // two scans of about 24k points
  StationarityDetector detector(settings);
  const auto stations = Replay(r.frames, &detector);
  ASSERT_FALSE(stations.empty());
  for (const auto& e : stations) {
    EXPECT_LE(e.station.cloud.size(), 50000u);
    EXPECT_EQ(e.station.merged_scan_utimes.size(), 2u);
  }
}

}  // namespace
}  // namespace fusecal
