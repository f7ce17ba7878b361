// Non-repetitive LiDAR models (simulator/scan_pattern.hpp): each frame samples other directions inside the
// model's field of view, coverage fills in over frames, points carry their firing times, and the shipped
// handheld scenarios load.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "runtime/sim/simulator/lidar.hpp"
#include "runtime/sim/simulator/scan_pattern.hpp"
#include "runtime/sim/simulator/scenario.hpp"
#include "runtime/sim/simulator/scene.hpp"
#include "tests/support/simulator_test_util.hpp"

namespace fusecal::sim {
namespace {

constexpr double kDeg = 180.0 / M_PI;

LidarParams Model(const std::string& model) {
  const std::string file = model == "rosette" ? "handheld-avia-pinhole.yaml" : "handheld-mid360-pinhole.yaml";
  return LoadScenario(testing::ScenarioPath(file)).lidar;
}

double AzimuthDeg(const Eigen::Vector3f& d) { return std::atan2(d.y(), d.x()) * kDeg; }
double ElevationDeg(const Eigen::Vector3f& d) { return std::asin(std::clamp(d.z(), -1.0f, 1.0f)) * kDeg; }

// Cells of 1 x 1 deg hit by the first `frames` frames.
size_t CoveredCells(const LidarParams& p, int frames) {
  std::set<std::pair<int, int>> cells;
  for (int f = 0; f < frames; ++f)
    for (const Eigen::Vector3f& d : PatternDirections(p, f))
      cells.insert({static_cast<int>(std::floor(AzimuthDeg(d))), static_cast<int>(std::floor(ElevationDeg(d)))});
  return cells.size();
}

TEST(ScanPattern, RosetteStaysInsideItsFieldOfView) {
  const LidarParams p = Model("rosette");
  EXPECT_EQ(p.beams, 6);
  EXPECT_EQ(p.Columns(), 4000);  // 240k points/s over 6 lines at 10 Hz
  const auto dirs = PatternDirections(p, 3);
  ASSERT_EQ(dirs.size(), 24000u);
  double max_az = 0, max_el = 0;
  for (const Eigen::Vector3f& d : dirs) {
    EXPECT_NEAR(d.norm(), 1.0f, 1e-5f);
    // Inside the ellipse of half-axes 35.2 x 38.6 deg.
    const double u = AzimuthDeg(d) / 35.2, v = ElevationDeg(d) / 38.6;
    EXPECT_LE(u * u + v * v, 1.0 + 1e-3);
    max_az = std::max(max_az, std::abs(AzimuthDeg(d)));
    max_el = std::max(max_el, std::abs(ElevationDeg(d)));
  }
  EXPECT_GT(max_az, 30.0);  // and reaches its rim
  EXPECT_GT(max_el, 33.0);
}

TEST(ScanPattern, PetalCoversTheWholeAzimuthBetweenItsElevations) {
  const LidarParams p = Model("petal");
  const auto dirs = PatternDirections(p, 0);
  ASSERT_EQ(dirs.size(), 20000u);
  std::set<int> azimuths;
  for (const Eigen::Vector3f& d : dirs) {
    EXPECT_GE(ElevationDeg(d), -7.0 - 1e-3);
    EXPECT_LE(ElevationDeg(d), 52.0 + 1e-3);
    azimuths.insert(std::min(35, static_cast<int>(std::floor((AzimuthDeg(d) + 180.0) / 10.0))));
  }
  EXPECT_EQ(azimuths.size(), 36u);
}

TEST(ScanPattern, FramesDifferAndCoverageFillsInOverASecond) {
  for (const std::string model : {"rosette", "petal"}) {
    SCOPED_TRACE(model);
    const LidarParams p = Model(model);
    EXPECT_NE(PatternDirections(p, 0), PatternDirections(p, 1));
    const size_t one = CoveredCells(p, 1), ten = CoveredCells(p, 10);
    EXPECT_GT(ten, one * 3 / 2) << "1 frame: " << one << " cells, 10 frames: " << ten;
    EXPECT_EQ(PatternDirections(p, 7), PatternDirections(p, 7));  // deterministic
  }
}

TEST(ScanPattern, ScansCarryLinesAndFiringTimes) {
  const Scenario s = LoadScenario(testing::ScenarioPath("handheld-avia-pinhole.yaml"));
  const Scene scene = BuildScene(s);
  const LidarSensor lidar(s.lidar);
  Isometry3 T_world_lidar = Isometry3::Identity();
  T_world_lidar.translation() = s.rig_position_m;
  const SimulatedScan a = lidar.ApplyNoise(lidar.CastClean(scene, T_world_lidar, 0, 0), 1);
  const SimulatedScan b = lidar.ApplyNoise(lidar.CastClean(scene, T_world_lidar, 0, 1), 1);
  ASSERT_GT(a.points.size(), 20000u);  // a room: almost every ray returns
  std::set<int> lines;
  for (const LidarPoint& pt : a.points) {
    lines.insert(pt.ring);
    EXPECT_GE(pt.time_offset_us, 0);
    EXPECT_LT(pt.time_offset_us, 100000);
  }
  EXPECT_EQ(lines.size(), 6u);
  EXPECT_NE(a.points.front().x, b.points.front().x);
}

}  // namespace
}  // namespace fusecal::sim
