// Bad input: one sensor only, duplicated and out-of-order timestamps, black / noise / invalid images,
// empty and all-NaN scans, flicker, moving objects, streams offset in time. Always: a clear status, no
// crash, no false station.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "runtime/sim/fixtures/stationarity_test_util.hpp"

namespace fusecal {
namespace {

using namespace fixtures;

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Replays and expects the same five good stations as the clean tiny recording.
void ExpectTheFiveStations(const std::vector<EmittedStation>& stations) {
  const Recording& r = TinyRecording();
  const Score score = ScoreStations(stations, r.truth, r.camera_station, r.scan_station, TinySettings().min_still_s);
  EXPECT_EQ(score.found, 5);
  EXPECT_EQ(score.missed + score.duplicates + score.during_motion, 0)
      << score.missed << " missed, " << score.duplicates << " duplicates, " << score.during_motion << " during motion";
}

TEST(StationarityBadInput, CameraOnlyStreamGivesNoStationAndSaysTheLidarIsMissing) {
  StationarityDetector detector(TinySettings());
  int fed = 0;
  for (const Frame& f : TinyRecording().frames) {
    if (!f.camera) continue;
    EXPECT_TRUE(detector.AddImage(f.utime, f.image).empty());
    ++fed;
  }
  const StationarityState st = detector.State();
  EXPECT_TRUE(st.lidar_missing);
  EXPECT_FALSE(st.camera_missing);
  EXPECT_EQ(st.phase, StationarityPhase::kMoving);
  EXPECT_TRUE(Contains(st.reason, "LiDAR")) << st.reason;
  EXPECT_TRUE(st.image_still);  // the camera alone would have said still
  EXPECT_EQ(st.counters.images_used, fed);
  EXPECT_FALSE(detector.Flush().has_value());
}

TEST(StationarityBadInput, LidarOnlyStreamGivesNoStationAndSaysTheCameraIsMissing) {
  StationarityDetector detector(TinySettings());
  for (const Frame& f : TinyRecording().frames) {
    if (f.camera) continue;
    EXPECT_TRUE(detector.AddScan(f.utime, f.cloud).empty());
  }
  const StationarityState st = detector.State();
  EXPECT_TRUE(st.camera_missing);
  EXPECT_FALSE(st.lidar_missing);
  EXPECT_EQ(st.phase, StationarityPhase::kMoving);
  EXPECT_TRUE(Contains(st.reason, "camera")) << st.reason;
  EXPECT_FALSE(detector.Flush().has_value());
}

TEST(StationarityBadInput, ASensorThatStopsIsReportedMissing) {
  const Recording& r = TinyRecording();
  StationarityDetector detector(TinySettings());
  const int64_t stop = r.frames.front().utime + 3'000'000;
  int stations_after_stop = 0;
  for (const Frame& f : r.frames) {
    if (f.camera) {
      const size_t n = detector.AddImage(f.utime, f.image).size();
      if (f.utime > stop + 1'000'000) stations_after_stop += static_cast<int>(n);
    } else if (f.utime <= stop) {
      detector.AddScan(f.utime, f.cloud);
    }
  }
  EXPECT_EQ(stations_after_stop, 0);
  const StationarityState st = detector.State();
  EXPECT_TRUE(st.lidar_missing);
  EXPECT_TRUE(Contains(st.reason, "no LiDAR scans for")) << st.reason;
}

TEST(StationarityBadInput, DuplicateAndOutOfOrderTimestampsAreIgnoredAndCounted) {
  const Recording& r = TinyRecording();
  std::vector<Frame> frames;
  int image_dups = 0, scan_dups = 0, image_late = 0, scan_late = 0;
  const Frame* previous_image = nullptr;
  const Frame* previous_scan = nullptr;
  for (size_t i = 0; i < r.frames.size(); ++i) {
    const Frame& f = r.frames[i];
    frames.push_back(f);
    if (i % 7 == 3) {  // the same timestamp again, other content (a black image, an empty scan)
      Frame dup = f;
      if (f.camera) {
        dup.image = cv::Mat(f.image.size(), f.image.type(), cv::Scalar::all(0));  // new buffer: never
                                                                                  // write into the recording
        ++image_dups;
      } else {
        dup.cloud = PointCloud();
        ++scan_dups;
      }
      frames.push_back(dup);
    }
    if (i % 11 == 5 && (f.camera ? previous_image : previous_scan)) {  // a late frame from the past
      frames.push_back(*(f.camera ? previous_image : previous_scan));
      (f.camera ? image_late : scan_late)++;
    }
    (f.camera ? previous_image : previous_scan) = &f;
  }
  ASSERT_GT(image_dups + scan_dups, 10);
  ASSERT_GT(image_late + scan_late, 10);
  StationarityDetector detector(TinySettings());
  std::vector<EmittedStation> stations;
  bool saw_duplicate_reason = false, saw_order_reason = false;
  for (const Frame& f : frames) {
    auto out = f.camera ? detector.AddImage(f.utime, f.image) : detector.AddScan(f.utime, f.cloud);
    for (auto& s : out) stations.push_back({std::move(s), f.utime});
    const std::string& why = detector.State().last_rejection;
    saw_duplicate_reason |= Contains(why, "duplicate timestamp");
    saw_order_reason |= Contains(why, "out of order");
  }
  const StationarityState st = detector.State();
  EXPECT_EQ(st.counters.images_duplicate, image_dups);
  EXPECT_EQ(st.counters.scans_duplicate, scan_dups);
  EXPECT_EQ(st.counters.images_out_of_order, image_late);
  EXPECT_EQ(st.counters.scans_out_of_order, scan_late);
  EXPECT_EQ(st.counters.images_without_texture, 0);  // the black duplicates were never looked at
  EXPECT_EQ(st.counters.scans_empty, 0);
  EXPECT_TRUE(saw_duplicate_reason);
  EXPECT_TRUE(saw_order_reason);
  ExpectTheFiveStations(stations);
}

TEST(StationarityBadInput, BlackFramesAreNotStill) {
  StationarityDetector detector(TinySettings());
  int images = 0;
  for (const Frame& f : TinyRecording().frames) {
    const auto out = f.camera ? detector.AddImage(f.utime, cv::Mat::zeros(f.image.size(), CV_8U))
                              : detector.AddScan(f.utime, f.cloud);
    EXPECT_TRUE(out.empty());
    images += f.camera;
  }
  const StationarityState st = detector.State();
  EXPECT_EQ(st.counters.images_without_texture, images);
  EXPECT_EQ(st.phase, StationarityPhase::kMoving);
  EXPECT_FALSE(st.image_still);
  EXPECT_TRUE(st.lidar_still);  // the LiDAR alone would have said still
  EXPECT_TRUE(Contains(st.reason, "without texture")) << st.reason;
  EXPECT_TRUE(std::isnan(st.image_flow_px));
}

TEST(StationarityBadInput, InterleavedBlackFramesPreventStillnessButNeverCrash) {
  // Every third image black: image stillness is never decided for min_still_s, no station.
  StationarityDetector detector(TinySettings());
  int n = 0, black = 0;
  for (const Frame& f : TinyRecording().frames) {
    std::vector<DetectedStation> out;
    if (f.camera) {
      const bool make_black = n++ % 3 == 2;
      black += make_black;
      out = detector.AddImage(f.utime, make_black ? cv::Mat::zeros(f.image.size(), CV_8U) : f.image);
    } else {
      out = detector.AddScan(f.utime, f.cloud);
    }
    EXPECT_TRUE(out.empty());
  }
  EXPECT_EQ(detector.State().counters.images_without_texture, black);
  EXPECT_FALSE(detector.Flush().has_value());
}

TEST(StationarityBadInput, NoiseFramesAreNotStill) {
  // Independent noise in every frame (a covered lens at high gain): corners exist but cannot be tracked.
  StationarityDetector detector(TinySettings());
  cv::RNG rng(5);
  const Recording& r = TinyRecording();
  for (const Frame& f : r.frames) {
    if (f.utime > r.truth[2].still_to_utime) break;  // three stops are enough
    std::vector<DetectedStation> out;
    if (f.camera) {
      cv::Mat noise(f.image.size(), CV_8U);
      rng.fill(noise, cv::RNG::NORMAL, 20, 8);
      out = detector.AddImage(f.utime, noise);
    } else {
      out = detector.AddScan(f.utime, f.cloud);
    }
    EXPECT_TRUE(out.empty());
  }
  const StationarityState st = detector.State();
  EXPECT_FALSE(st.image_still);
  EXPECT_GT(st.counters.images_untracked + st.counters.images_without_texture, 45);
  EXPECT_EQ(st.counters.stations_emitted, 0);
}

TEST(StationarityBadInput, InvalidImagesAreIgnoredAndCounted) {
  StationarityDetector detector(TinySettings());
  std::vector<EmittedStation> stations;
  int invalid = 0;
  for (const Frame& f : TinyRecording().frames) {
    if (f.camera && invalid < 30) {
      const cv::Mat bad[] = {cv::Mat(), cv::Mat(f.image.size(), CV_16UC1, cv::Scalar(1000)),
                             cv::Mat(f.image.size(), CV_32FC3, cv::Scalar(0.5, 0.5, 0.5))};
      EXPECT_TRUE(detector.AddImage(f.utime - 1, bad[invalid % 3]).empty());
      ++invalid;
    }
    auto out = f.camera ? detector.AddImage(f.utime, f.image) : detector.AddScan(f.utime, f.cloud);
    for (auto& s : out) stations.push_back({std::move(s), f.utime});
  }
  const StationarityState st = detector.State();
  EXPECT_EQ(st.counters.images_invalid, invalid);
  EXPECT_EQ(st.counters.images_received - st.counters.images_used, invalid);
  EXPECT_TRUE(Contains(st.last_rejection, "not an 8-bit")) << st.last_rejection;
  ExpectTheFiveStations(stations);
}

TEST(StationarityBadInput, TinyAndOddImagesDoNotCrash) {
  StationarityDetector detector(TinySettings());
  const cv::Mat odd[] = {cv::Mat(1, 1, CV_8U, cv::Scalar(9)), cv::Mat(2, 100, CV_8UC3, cv::Scalar(1, 2, 3)),
                         cv::Mat(100, 2, CV_8U, cv::Scalar(200)), cv::Mat(5, 7, CV_8UC4, cv::Scalar::all(77)),
                         cv::Mat(3000, 4, CV_8U, cv::Scalar(0))};
  int64_t t = 1'000'000;
  for (int round = 0; round < 3; ++round)
    for (const cv::Mat& m : odd) EXPECT_TRUE(detector.AddImage(t += 100000, m).empty());
  const StationarityState st = detector.State();
  EXPECT_EQ(st.counters.images_used, 15);
  EXPECT_EQ(st.counters.images_without_texture, 15);
  EXPECT_FALSE(st.image_still);
}

TEST(StationarityBadInput, EmptyAndAllNanScansAreIgnoredAndCounted) {
  StationarityDetector detector(TinySettings());
  std::vector<EmittedStation> stations;
  int n = 0, bad = 0;
  for (const Frame& f : TinyRecording().frames) {
    std::vector<DetectedStation> out;
    if (f.camera) {
      out = detector.AddImage(f.utime, f.image);
    } else {
      PointCloud cloud = f.cloud;
      if (n % 4 == 1) {
        cloud = PointCloud();
        ++bad;
      } else if (n % 4 == 3) {
        for (auto& p : cloud.points) p = Eigen::Vector3f::Constant(NAN);
        ++bad;
      }
      ++n;
      out = detector.AddScan(f.utime, cloud);
    }
    for (auto& s : out) stations.push_back({std::move(s), f.utime});
  }
  const StationarityState st = detector.State();
  EXPECT_EQ(st.counters.scans_empty, bad);
  EXPECT_EQ(st.counters.scans_used, n - bad);
  ExpectTheFiveStations(stations);
  for (const auto& s : stations) EXPECT_GT(s.station.cloud.size(), 1000u);  // never an empty station cloud
}

TEST(StationarityBadInput, OnlyEmptyScansMeanTheLidarIsMissing) {
  StationarityDetector detector(TinySettings());
  for (const Frame& f : TinyRecording().frames) {
    const auto out = f.camera ? detector.AddImage(f.utime, f.image) : detector.AddScan(f.utime, PointCloud());
    EXPECT_TRUE(out.empty());
  }
  const StationarityState st = detector.State();
  EXPECT_TRUE(st.lidar_missing);
  EXPECT_GT(st.counters.scans_empty, 90);
  EXPECT_TRUE(Contains(st.last_rejection, "ignored as empty")) << st.last_rejection;
}

TEST(StationarityBadInput, FlickerAndExposureChangesDoNotBreakStillness) {
  // Every other image 35 % darker, plus a slow exposure ramp.
  std::vector<Frame> frames = TinyRecording().frames;
  int n = 0;
  for (Frame& f : frames) {
    if (!f.camera) continue;
    const double gain = (n % 2 ? 0.65 : 1.0) * (1.0 + 0.003 * n);
    cv::Mat changed;  // a new buffer: the recording is shared by the tests
    f.image.convertTo(changed, CV_8U, gain, n % 2 ? 6 : 0);
    f.image = changed;
    ++n;
  }
  StationarityDetector detector(TinySettings());
  ExpectTheFiveStations(Replay(frames, &detector));
}

TEST(StationarityBadInput, AnObjectMovingInFrontOfTheStillRigDoesNotPreventStillness) {
  // A textured block (a fifth of the image) crosses the view at 6 px per frame.
  std::vector<Frame> frames = TinyRecording().frames;
  cv::Mat block(110, 180, CV_8U);
  cv::RNG rng(9);
  rng.fill(block, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(block, block, cv::Size(0, 0), 1.5);
  int n = 0;
  for (Frame& f : frames) {
    if (!f.camera) continue;
    f.image = f.image.clone();
    const int x = (n++ * 6) % (f.image.cols - block.cols);
    block.copyTo(f.image(cv::Rect(x, 70, block.cols, block.rows)));
  }
  StationarityDetector detector(TinySettings());
  ExpectTheFiveStations(Replay(frames, &detector));
}

TEST(StationarityBadInput, StreamsFarApartInTimeGiveNoStation) {
  // The LiDAR clock runs 10 s ahead of the camera's: its frames arrive with the camera's but never share
  // an interval with them.
  StationarityDetector detector(TinySettings());
  for (const Frame& f : TinyRecording().frames) {
    const auto out = f.camera ? detector.AddImage(f.utime, f.image) : detector.AddScan(f.utime + 10'000'000, f.cloud);
    EXPECT_TRUE(out.empty());
  }
  EXPECT_TRUE(detector.State().camera_missing);
  EXPECT_FALSE(detector.Flush().has_value());
}

TEST(StationarityBadInput, FlushEmitsAPendingStopThenAcceptsANewStream) {
  // The scans stop 0.45 s into the first stop, the images go on to its end: measured to the lagging
  // sensor the stop is too short, measured to the end of the streams it is long enough.
  const Recording& r = TinyRecording();
  StationarityDetector detector(TinySettings());
  const int64_t scans_until = r.truth[0].still_from_utime + 450000;
  for (const Frame& f : r.frames) {
    if (f.station_id != 0) continue;
    if (!f.camera && f.utime > scans_until) continue;
    EXPECT_TRUE((f.camera ? detector.AddImage(f.utime, f.image) : detector.AddScan(f.utime, f.cloud)).empty());
  }
  EXPECT_EQ(detector.State().phase, StationarityPhase::kSettling);
  const std::optional<DetectedStation> flushed = detector.Flush();
  ASSERT_TRUE(flushed.has_value());
  EXPECT_EQ(flushed->id, 0);
  EXPECT_LE(flushed->scan_utime, scans_until);
  EXPECT_FALSE(detector.Flush().has_value());  // nothing left
  // After Flush the timestamps may start over: the whole recording again. Its first stop is where the
  // flushed station was taken (same place, suppressed); the other four give stations 1..4.
  const auto stations = Replay(r.frames, &detector);
  ASSERT_EQ(stations.size(), 4u);
  for (size_t i = 0; i < stations.size(); ++i) {
    EXPECT_EQ(stations[i].station.id, static_cast<int>(i) + 1);
    EXPECT_EQ(r.camera_station.at(stations[i].station.image_utime), static_cast<int>(i) + 1);
  }
  const StationarityState st = detector.State();
  EXPECT_EQ(st.counters.stations_same_place, 1);
  EXPECT_EQ(st.counters.images_out_of_order, 0);
}

}  // namespace
}  // namespace fusecal
