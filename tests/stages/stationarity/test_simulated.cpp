// Simulated recordings (runtime/sim/simulator, the tiny scenario): every true still interval gives exactly one
// station, none comes during motion, and each lies inside its interval.
#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "runtime/sim/fixtures/stationarity_test_util.hpp"

namespace fusecal {
namespace {

using namespace fixtures;

// Checks every station against the recording's truth; returns the number of problems (each reported).
void ExpectOneStationPerInterval(const Recording& r, const std::vector<EmittedStation>& stations,
                                 const StationaritySettings& settings) {
  const Score score = ScoreStations(stations, r.truth, r.camera_station, r.scan_station, settings.min_still_s);
  EXPECT_EQ(score.true_intervals, static_cast<int>(r.truth.size()));
  EXPECT_EQ(score.found, score.true_intervals);
  EXPECT_EQ(score.missed, 0);
  EXPECT_EQ(score.duplicates, 0);
  EXPECT_EQ(score.during_motion, 0);
  EXPECT_LE(score.worst_latency_s, 0.5);
  ASSERT_EQ(stations.size(), r.truth.size());
  for (size_t i = 0; i < stations.size(); ++i) {
    const DetectedStation& s = stations[i].station;
    const sim::Station& t = r.truth[i];
    SCOPED_TRACE("station " + std::to_string(i));
    EXPECT_EQ(s.id, static_cast<int>(i));
    EXPECT_EQ(s.utime, std::max(s.image_utime, s.scan_utime));
    EXPECT_LE(std::llabs(s.image_utime - s.scan_utime), std::llround(settings.max_pair_dt_s * 1e6));
    // The pair lies in the detected interval, the detected interval is long enough, and the station's
    // image and scan (its whole sweep) were taken inside the true interval.
    EXPECT_LE(s.still_from, std::min(s.image_utime, s.scan_utime));
    EXPECT_GE(s.still_to, s.utime);
    EXPECT_GE(s.still_to - s.still_from, std::llround(settings.min_still_s * 1e6));
    EXPECT_GE(s.utime, t.still_from_utime);
    EXPECT_LE(s.utime, t.still_to_utime);
    EXPECT_EQ(r.camera_station.at(s.image_utime), t.id);
    EXPECT_EQ(r.scan_station.at(s.scan_utime), t.id);
    // Emitted while the rig still stands there, at most 0.5 s after min_still_s has passed.
    EXPECT_LE(stations[i].emitted_at, t.still_to_utime);
    EXPECT_LE(stations[i].emitted_at - t.still_from_utime, std::llround((settings.min_still_s + 0.5) * 1e6));
    EXPECT_FALSE(s.image.empty());
    EXPECT_GT(s.cloud.size(), 1000u);
    EXPECT_EQ(s.merged_scan_utimes, std::vector<int64_t>{s.scan_utime});
    EXPECT_LE(s.image_drift_px, settings.image.max_drift_px);
    EXPECT_LE(s.lidar_change_m, settings.lidar.max_drift_m);
  }
}

TEST(SimulatedStationarity, TinyScenarioGivesOneStationPerStillInterval) {
  const Recording& r = TinyRecording();
  ASSERT_EQ(r.truth.size(), 5u);
  const StationaritySettings settings = TinySettings();
  StationarityDetector detector(settings);
  const auto stations = Replay(r.frames, &detector);
  ExpectOneStationPerInterval(r, stations, settings);
  const StationarityState st = detector.State();
  EXPECT_EQ(st.counters.stations_emitted, 5);
  EXPECT_EQ(st.counters.images_used, st.counters.images_received);
  EXPECT_EQ(st.counters.scans_used, st.counters.scans_received);
  EXPECT_EQ(st.counters.images_without_texture, 0);
  EXPECT_EQ(st.next_station_id, 5);
}

TEST(SimulatedStationarity, DefaultSettingsWithTwoSecondStops) {
  const Recording& r = TinyLongStillRecording();
  ASSERT_EQ(r.truth.size(), 5u);
  const StationaritySettings settings;
  StationarityDetector detector(settings);
  ExpectOneStationPerInterval(r, Replay(r.frames, &detector), settings);
}

TEST(SimulatedStationarity, StopsShorterThanMinStillGiveNoStation) {
  const Recording& r = TinyRecording();  // 1 s stops
  StationaritySettings settings;
  settings.min_still_s = 1.5;
  StationarityDetector detector(settings);
  for (const Frame& f : r.frames) {
    const auto out = f.camera ? detector.AddImage(f.utime, f.image) : detector.AddScan(f.utime, f.cloud);
    EXPECT_TRUE(out.empty());
    EXPECT_NE(detector.State().phase, StationarityPhase::kStill);
  }
  EXPECT_FALSE(detector.Flush().has_value());
}

TEST(SimulatedStationarity, PhaseIsMovingDuringMotion) {
  const Recording& r = TinyRecording();
  const StationaritySettings settings = TinySettings();
  StationarityDetector detector(settings);
  int moving_checked = 0, still_checked = 0;
  for (const Frame& f : r.frames) {
    if (f.camera)
      detector.AddImage(f.utime, f.image);
    else
      detector.AddScan(f.utime, f.cloud);
    const StationarityState st = detector.State();
    // Clearly moving: more than 0.3 s away from every still interval (the minimum-jerk ends are slow).
    bool near_still = false;
    for (const auto& t : r.truth)
      near_still |= f.utime > t.still_from_utime - 300000 && f.utime < t.still_to_utime + 300000;
    if (!near_still) {
      ++moving_checked;
      EXPECT_EQ(st.phase, StationarityPhase::kMoving) << "t=" << f.utime << " " << st.reason;
      EXPECT_FALSE(st.image_still) << "t=" << f.utime << " flow " << st.image_flow_px;
    }
    // Well inside a still interval (from 0.3 s after its start) the image is judged still.
    for (const auto& t : r.truth) {
      if (f.camera && f.utime > t.still_from_utime + 300000 && f.utime < t.still_to_utime) {
        ++still_checked;
        EXPECT_TRUE(st.image_still) << "t=" << f.utime << " " << st.reason;
        EXPECT_LT(st.image_flow_px, settings.image.still_flow_px);
        EXPECT_NE(st.phase, StationarityPhase::kMoving) << "t=" << f.utime << " " << st.reason;
      }
    }
  }
  EXPECT_GT(moving_checked, 40);
  EXPECT_GT(still_checked, 25);
}

TEST(SimulatedStationarity, ColourImagesWorkAlike) {
  const Recording& r = TinyRecording();
  std::vector<Frame> colour = r.frames;
  for (Frame& f : colour)
    if (f.camera) cv::cvtColor(f.image, f.image, cv::COLOR_GRAY2BGR);  // a new buffer (3 channels)
  const StationaritySettings settings = TinySettings();
  StationarityDetector detector(settings);
  const auto stations = Replay(colour, &detector);
  ExpectOneStationPerInterval(r, stations, settings);
  for (const auto& s : stations) EXPECT_EQ(s.station.image.type(), CV_8UC3);
}

TEST(SimulatedStationarity, MergedScansDensifyTheStationCloud) {
  const Recording& r = TinyRecording();
  StationaritySettings settings = TinySettings();
  settings.merge_scans = 3;
  StationarityDetector detector(settings);
  const auto stations = Replay(r.frames, &detector);
  ASSERT_EQ(stations.size(), 5u);
  for (const auto& e : stations) {
    const DetectedStation& s = e.station;
    ASSERT_EQ(s.merged_scan_utimes.size(), 3u);
    EXPECT_EQ(s.merged_scan_utimes.back(), s.scan_utime);
    EXPECT_TRUE(std::is_sorted(s.merged_scan_utimes.begin(), s.merged_scan_utimes.end()));
    EXPECT_GE(s.merged_scan_utimes.front(), s.still_from);
    size_t total = 0;
    for (int64_t u : s.merged_scan_utimes) {
      EXPECT_EQ(r.scan_station.at(u), s.id);  // every merged scan was taken while still at this station
      for (const Frame& f : r.frames)
        if (!f.camera && f.utime == u) total += f.cloud.size();
    }
    EXPECT_EQ(s.cloud.size(), total);
    EXPECT_EQ(s.cloud.intensity.size(), total);
    EXPECT_EQ(s.cloud.ring.size(), total);
    ASSERT_EQ(s.cloud.time_offset_s.size(), total);
    // Point times are relative to the chosen scan: the oldest scan's points come 0.2 s earlier.
    const double oldest = (s.merged_scan_utimes.front() - s.scan_utime) * 1e-6;
    EXPECT_NEAR(s.cloud.time_offset_s.front(), oldest, 1e-3);
    EXPECT_NEAR(s.cloud.time_offset_s.back(), 0.1, 1e-2);
  }
}

// Frames of one true still interval, repeated with continuing timestamps for `seconds` from `start`.
std::vector<Frame> StandAt(const Recording& r, int station, double seconds, int64_t start) {
  std::vector<const Frame*> own;
  for (const Frame& f : r.frames)
    if (f.station_id == station) own.push_back(&f);
  int64_t first = own.front()->utime, last_image = first;
  for (const Frame* f : own) {
    first = std::min(first, f->utime);
    if (f->camera) last_image = std::max(last_image, f->utime);
  }
  const int64_t period = last_image - first + 100000;  // the camera's 10 Hz continues seamlessly
  std::vector<Frame> out;
  for (int64_t base = 0; base < std::llround(seconds * 1e6); base += period) {
    for (const Frame* f : own) {
      Frame g = *f;
      g.utime = start + base + (f->utime - first);
      out.push_back(std::move(g));
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const Frame& a, const Frame& b) { return a.utime < b.utime; });
  return out;
}

TEST(SimulatedStationarity, StandingStillLongGivesOneStationOnly) {
  const Recording& r = TinyRecording();
  StationarityDetector detector(TinySettings());
  const auto stations = Replay(StandAt(r, 0, 6.0, 1'000'000), &detector);
  EXPECT_EQ(stations.size(), 1u);
  EXPECT_EQ(detector.State().counters.stations_emitted, 1);
}

TEST(SimulatedStationarity, AGlitchWhileStandingGivesNoSecondStation) {
  // A frame from the middle of a motion interrupts the stillness; the rig settles again at the same
  // place: suppressed, counted.
  const Recording& r = TinyRecording();
  std::vector<Frame> frames = StandAt(r, 0, 4.0, 1'000'000);
  const Frame* moving_image = nullptr;
  for (const Frame& f : r.frames)
    if (f.camera && f.utime > r.truth[0].still_to_utime + 500000) {
      moving_image = &f;
      break;
    }
  ASSERT_NE(moving_image, nullptr);
  for (Frame& f : frames)
    if (f.camera && f.utime > 2'500'000) {
      f.image = moving_image->image;  // one glitched image, 1.5 s into standing
      break;
    }
  StationarityDetector detector(TinySettings());
  const auto stations = Replay(frames, &detector);
  EXPECT_EQ(stations.size(), 1u);
  const StationarityState st = detector.State();
  EXPECT_EQ(st.counters.stations_same_place, 1);
  EXPECT_EQ(st.phase, StationarityPhase::kMoving);  // after Flush: no data
}

TEST(SimulatedStationarity, AMoveToAnotherPlaceGivesANewStation) {
  const Recording& r = TinyRecording();
  std::vector<Frame> frames = StandAt(r, 0, 2.0, 1'000'000);
  const std::vector<Frame> second = StandAt(r, 1, 2.0, 3'000'000);
  frames.insert(frames.end(), second.begin(), second.end());
  StationarityDetector detector(TinySettings());
  const auto stations = Replay(frames, &detector);
  ASSERT_EQ(stations.size(), 2u);
  EXPECT_EQ(stations[0].station.id, 0);
  EXPECT_EQ(stations[1].station.id, 1);
  EXPECT_LT(stations[0].station.utime, 3'000'000);
  EXPECT_GT(stations[1].station.still_from, 3'000'000 - 1);
}

}  // namespace
}  // namespace fusecal
