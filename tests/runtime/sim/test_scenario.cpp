// Scenario files: the shipped ones load; bad ones fail with a ConfigError naming the key.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "runtime/config_reader.hpp"
#include "runtime/sim/simulator/scenario.hpp"
#include "tests/support/simulator_test_util.hpp"

namespace fusecal::sim {
namespace {

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Writes text to a temporary scenario file and loads it. The file is this process's own: ctest runs
// these tests in parallel, one process each (a shared name let one test read another's scenario).
Scenario LoadText(const std::string& text) {
  const std::string path = ::testing::TempDir() + "/scenario_under_test_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(path) << text;
  return LoadScenario(path);
}

const auto Replace = testing::ReplaceFirst;

// Expects LoadText(text) to throw a ConfigError whose message contains `key`.
void ExpectErrorNaming(const std::string& text, const std::string& key) {
  testing::ExpectConfigErrorNaming([](const std::string& t) { LoadText(t); }, text, key);
}

class SimBadScenario : public ::testing::Test {
 protected:
  const std::string base_ = ReadFile(testing::ScenarioPath("tiny-equirect.yaml"));
};

TEST(SimScenario, ShippedScenariosLoad) {
  for (const char* name : {"indoor-equirect-hdl64.yaml", "indoor-pinhole-hdl64.yaml", "outdoor-equirect-hdl64.yaml",
                           "tiny-equirect.yaml", "handheld-avia-pinhole.yaml", "handheld-mid360-pinhole.yaml"}) {
    SCOPED_TRACE(name);
    Scenario s;
    ASSERT_NO_THROW(s = LoadScenario(testing::ScenarioPath(name)));
    EXPECT_TRUE(s.camera().params.Validate().empty());
    EXPECT_TRUE(IsValidTransform(s.T_camera_lidar()));
  }
}

TEST(SimScenario, DefaultScenarioValues) {
  const Scenario s = LoadScenario(testing::ScenarioPath("indoor-equirect-hdl64.yaml"));
  EXPECT_EQ(s.scene, "indoor");
  EXPECT_EQ(s.camera().params.model, "equirectangular");
  EXPECT_EQ(s.camera().params.width, 2048);
  EXPECT_EQ(s.camera().params.height, 1024);
  EXPECT_EQ(s.lidar.beams, 64);
  EXPECT_EQ(s.lidar.Columns(), 2000);
  EXPECT_EQ(s.motions.horizontal, 5);
  EXPECT_EQ(s.motions.vertical, 5);
  EXPECT_DOUBLE_EQ(s.motions.still_s, 3.0);
  // The camera looks along the LiDAR's x axis, about 13 cm from it.
  const Eigen::Vector3d forward = s.T_camera_lidar().linear() * Eigen::Vector3d::UnitX();
  EXPECT_GT(forward.z(), 0.99);
  EXPECT_NEAR(s.T_camera_lidar().inverse().translation().norm(), 0.133, 0.005);
  const std::vector<double> el = s.lidar.ElevationsRad();
  ASSERT_EQ(el.size(), 64u);
  EXPECT_NEAR(el.front() * 180 / M_PI, 2.0, 1e-9);
  EXPECT_NEAR(el.back() * 180 / M_PI, -24.8, 1e-9);
}

TEST(SimScenario, PinholeNinetyDegrees) {
  const Scenario s = LoadScenario(testing::ScenarioPath("indoor-pinhole-hdl64.yaml"));
  EXPECT_EQ(s.camera().params.model, "pinhole");
  EXPECT_NEAR(2.0 * std::atan(s.camera().params.width / 2.0 / s.camera().params.fx) * 180 / M_PI, 90.0, 0.1);
}

TEST_F(SimBadScenario, BaseIsValid) { EXPECT_NO_THROW(LoadText(base_)); }

TEST_F(SimBadScenario, UnknownTopLevelKey) { ExpectErrorNaming(base_ + "colour_space: srgb\n", "colour_space"); }

TEST_F(SimBadScenario, UnknownNestedKey) {
  ExpectErrorNaming(Replace(base_, "  width: 512\n", "  width: 512\n  exposure_ms: 3\n"), "camera.exposure_ms");
}

TEST_F(SimBadScenario, NegativeWidth) {
  ExpectErrorNaming(Replace(base_, "  width: 512\n", "  width: -512\n"), "camera.width");
}

TEST_F(SimBadScenario, SizesBeyondMemoryNameTheirKey) {
  ExpectErrorNaming(Replace(base_, "  width: 512\n", "  width: 2000000000\n"), "camera.width");
  const std::string dense = Replace(base_, "  beams: 16\n", "  beams: 4096\n");
  ExpectErrorNaming(Replace(dense, "  azimuth_resolution_deg: 1.0\n", "  azimuth_resolution_deg: 0.01\n"),
                    "lidar.azimuth_resolution_deg");
  ExpectErrorNaming(Replace(base_, "  still_s: 1.5", "  still_s: 1.0e9"), "motions");
}

TEST_F(SimBadScenario, NonRepetitiveModels) {
  const std::string rosette = Replace(base_, "  model: multibeam\n", "  model: rosette\n");
  ExpectErrorNaming(Replace(rosette, "  beams: 16\n", "  beams: 6\n  point_rate_hz: 1.0e12\n"), "lidar.point_rate_hz");
  ExpectErrorNaming(Replace(rosette, "  beams: 16\n", "  field_of_view_deg: [70, 200]\n"), "lidar.field_of_view_deg");
  const Scenario s = LoadText(Replace(rosette, "  beams: 16\n", ""));  // beams: the model's 6 lines
  EXPECT_EQ(s.lidar.beams, 6);
  EXPECT_FALSE(s.lidar.Repetitive());
}

TEST_F(SimBadScenario, UnknownCameraModel) {
  ExpectErrorNaming(Replace(base_, "  model: equirectangular\n", "  model: fisheye\n"), "camera.model");
}

TEST_F(SimBadScenario, UnknownLidarModel) {
  ExpectErrorNaming(Replace(base_, "  model: multibeam\n", "  model: flash\n"), "lidar.model");
}

TEST_F(SimBadScenario, UnknownScene) {
  ExpectErrorNaming(Replace(base_, "scene: indoor\n", "scene: forest\n"), "scene");
}

TEST_F(SimBadScenario, MissingRequiredKey) {
  ExpectErrorNaming(Replace(base_, "  beams: 16\n", ""), "lidar.beams");
  ExpectErrorNaming(Replace(base_, "seed: 7\n", ""), "seed");
}

TEST_F(SimBadScenario, WrongListSize) {
  ExpectErrorNaming(Replace(base_, "  xyz_m: [0.0295, 0.1218, -0.0458]\n", "  xyz_m: [0.1, 0.2]\n"), "extrinsic.xyz_m");
  ExpectErrorNaming(Replace(base_, "  rotation_deg: [10, 20]\n", "  rotation_deg: [20, 10]\n"), "motions.rotation_deg");
}

TEST_F(SimBadScenario, NegativeNoise) {
  ExpectErrorNaming(Replace(base_, "  image_sigma: 2.0\n", "  image_sigma: -1\n"), "noise.image_sigma");
}

TEST_F(SimBadScenario, PinholeNeedsFocalLength) {
  ExpectErrorNaming(Replace(base_, "  model: equirectangular\n", "  model: pinhole\n"), "camera.fx");
}

TEST_F(SimBadScenario, ExtrinsicChangesParse) {
  EXPECT_TRUE(LoadText(base_).extrinsic_changes.empty());
  const Scenario s = LoadText(base_ +
                              "extrinsic_changes:\n"
                              "  - after_stop: 2\n"
                              "    delta_rpy_deg: [1.0, 0, 0]\n"
                              "    delta_xyz_m: [0.02, 0, 0]\n"
                              "  - {after_stop: 4, delta_rpy_deg: [0, 0, -2], delta_xyz_m: [0, 0, 0.01]}\n");
  ASSERT_EQ(s.extrinsic_changes.size(), 2u);
  EXPECT_EQ(s.extrinsic_changes[0].after_stop, 2);
  EXPECT_EQ(s.extrinsic_changes[1].after_stop, 4);  // tiny: 5 stops, the 4th is the last with a motion after it
  EXPECT_TRUE(
      s.extrinsic_changes[0].delta.isApprox(MakeIsometry(RotationFromRpy(M_PI / 180, 0, 0), {0.02, 0, 0}), 1e-12));
  EXPECT_NEAR(s.extrinsic_changes[1].delta.translation().z(), 0.01, 1e-15);
  EXPECT_NEAR(RpyFromRotation(s.extrinsic_changes[1].delta.linear()).z(), -2 * M_PI / 180, 1e-12);
}

TEST_F(SimBadScenario, BadExtrinsicChanges) {
  const auto change = [&](const std::string& entries) { return base_ + "extrinsic_changes:\n" + entries; };
  const std::string ok = "  - {after_stop: 1, delta_rpy_deg: [1, 0, 0], delta_xyz_m: [0, 0, 0]}\n";
  for (const char* stop : {"0", "5", "-1"})  // tiny has 5 stops: no motion after the 5th
    ExpectErrorNaming(change("  - {after_stop: " + std::string(stop) +
                             ", delta_rpy_deg: [1, 0, 0], "
                             "delta_xyz_m: [0, 0, 0]}\n"),
                      "extrinsic_changes[0].after_stop");
  ExpectErrorNaming(change(ok + ok), "extrinsic_changes[1].after_stop");  // two at one stop
  ExpectErrorNaming(change("  - {after_stop: 3, delta_rpy_deg: [1, 0, 0], delta_xyz_m: [0, 0, 0]}\n" + ok),
                    "extrinsic_changes[1].after_stop");  // out of order
  ExpectErrorNaming(change("  - {after_stop: 1.5, delta_rpy_deg: [1, 0, 0], delta_xyz_m: [0, 0, 0]}\n"),
                    "extrinsic_changes[0].after_stop");
  ExpectErrorNaming(change("  - {after_stop: 1, delta_rpy_deg: [1, .nan, 0], delta_xyz_m: [0, 0, 0]}\n"),
                    "extrinsic_changes[0].delta_rpy_deg");
  ExpectErrorNaming(change("  - {after_stop: 1, delta_rpy_deg: [1, 0, 0], delta_xyz_m: [0, .inf, 0]}\n"),
                    "extrinsic_changes[0].delta_xyz_m");
  ExpectErrorNaming(change("  - {after_stop: 1, delta_rpy_deg: [1, 0], delta_xyz_m: [0, 0, 0]}\n"),
                    "extrinsic_changes[0].delta_rpy_deg");
  ExpectErrorNaming(change("  - {after_stop: 1, delta_rpy_deg: [1, 0, 0]}\n"), "extrinsic_changes[0].delta_xyz_m");
  ExpectErrorNaming(change(ok + "  - {after_stop: 2, delta_rpy_deg: [1, 0, 0], delta_xyz_m: [0, 0, 0], when: 3}\n"),
                    "extrinsic_changes[1].when");
  ExpectErrorNaming(change("  - 4\n"), "extrinsic_changes[0]");
  ExpectErrorNaming(base_ + "extrinsic_changes: {after_stop: 1}\n", "extrinsic_changes");
}

TEST(SimScenario, MissingFileIsConfigError) {
  EXPECT_THROW(LoadScenario(::testing::TempDir() + "/no-such-scenario.yaml"), ConfigError);
}

}  // namespace
}  // namespace fusecal::sim
