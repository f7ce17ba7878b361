#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "stages/stationarity/stationarity_detector.hpp"

namespace fusecal {
namespace {

TEST(StationaritySettings, DefaultsAreValid) {
  EXPECT_EQ(StationaritySettings().Validate(), "");
  EXPECT_EQ(ImageMotionSettings().Validate(), "");
  EXPECT_EQ(LidarChangeSettings().Validate(), "");
  EXPECT_EQ(StationaritySettings().min_still_s, 1.0);
  EXPECT_EQ(StationaritySettings().merge_scans, 1);  // densifying is off by default
}

TEST(StationaritySettings, InvalidValuesNameTheirKey) {
  struct Case {
    void (*mutate)(StationaritySettings*);
    const char* key;
  };
  const Case cases[] = {
      {[](StationaritySettings* s) { s->min_still_s = 0; }, "min_still_s"},
      {[](StationaritySettings* s) { s->min_still_s = NAN; }, "min_still_s"},
      {[](StationaritySettings* s) { s->max_pair_dt_s = -0.1; }, "max_pair_dt_s"},
      {[](StationaritySettings* s) { s->merge_scans = 0; }, "merge_scans"},
      {[](StationaritySettings* s) { s->moved_flow_px = 0; }, "moved_flow_px"},
      {[](StationaritySettings* s) { s->moved_change_m = -1; }, "moved_change_m"},
      {[](StationaritySettings* s) { s->max_frame_gap_s = INFINITY; }, "max_frame_gap_s"},
      {[](StationaritySettings* s) { s->sensor_timeout_s = 0; }, "sensor_timeout_s"},
      {[](StationaritySettings* s) { s->max_buffered_frames = 1; }, "max_buffered_frames"},
      {[](StationaritySettings* s) { s->image.max_corners = 3; }, "image.max_corners"},
      {[](StationaritySettings* s) { s->image.klt_window_px = 20; }, "image.klt_window_px"},
      {[](StationaritySettings* s) { s->image.still_flow_px = 0; }, "image.still_flow_px"},
      {[](StationaritySettings* s) { s->image.min_tracks = 500; }, "image.min_tracks"},
      {[](StationaritySettings* s) { s->image.working_width_px = 10; }, "image.working_width_px"},
      {[](StationaritySettings* s) { s->lidar.change_quantile = 1.5; }, "lidar.change_quantile"},
      {[](StationaritySettings* s) { s->lidar.still_change_m = 0; }, "lidar.still_change_m"},
      {[](StationaritySettings* s) { s->lidar.max_range_m = 0.5; }, "lidar.max_range_m"},
      {[](StationaritySettings* s) { s->lidar.azimuth_bin_deg = 0; }, "lidar.azimuth_bin_deg"},
  };
  for (const Case& c : cases) {
    StationaritySettings s;
    c.mutate(&s);
    const std::string problem = s.Validate();
    EXPECT_EQ(problem.rfind(std::string(c.key) + ":", 0), 0u) << "expected '" << c.key << "', got '" << problem << "'";
  }
}

TEST(StationaritySettings, DetectorRejectsInvalidSettingsWithTheMessage) {
  StationaritySettings s;
  s.min_still_s = -1;
  try {
    StationarityDetector detector(s);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("min_still_s"), std::string::npos) << e.what();
  }
}

TEST(StationaritySettings, PhaseNames) {
  EXPECT_STREQ(ToString(StationarityPhase::kMoving), "moving");
  EXPECT_STREQ(ToString(StationarityPhase::kSettling), "settling");
  EXPECT_STREQ(ToString(StationarityPhase::kStill), "still");
}

TEST(StationarityDetector, FreshStateIsMovingWithNoData) {
  StationarityDetector detector{StationaritySettings()};
  const StationarityState s = detector.State();
  EXPECT_EQ(s.phase, StationarityPhase::kMoving);
  EXPECT_EQ(s.reason, "no data yet");
  EXPECT_FALSE(s.camera_missing);
  EXPECT_FALSE(s.lidar_missing);
  EXPECT_EQ(s.next_station_id, 0);
  EXPECT_FALSE(detector.Flush().has_value());
}

}  // namespace
}  // namespace fusecal
