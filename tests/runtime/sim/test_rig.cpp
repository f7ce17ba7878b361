// Rigs of several cameras (scenario cameras:): parsing and errors that name the entry, each camera's own
// frame times, seeds, caches and extrinsic changes, and one-camera scenarios unchanged by it all.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "runtime/config_reader.hpp"
#include "runtime/sim/simulator/random.hpp"
#include "runtime/sim/simulator/render.hpp"
#include "runtime/sim/simulator/simulation.hpp"
#include "tests/support/simulator_test_util.hpp"

namespace fusecal::sim {
namespace {

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

const auto Replace = testing::ReplaceFirst;

// Expects ParseScenario(text) to throw a ConfigError whose message contains `key`.
void ExpectErrorNaming(const std::string& text, const std::string& key) {
  testing::ExpectConfigErrorNaming([](const std::string& t) { ParseScenario(t); }, text, key);
}

bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

// tiny-pinhole.yaml's camera: and extrinsic: sections.
const char* const kOneCamera =
    "camera:\n"
    "  model: pinhole\n"
    "  width: 640\n"
    "  height: 480\n"
    "  fx: 320.0\n"
    "  fy: 320.0\n"
    "  cx: 319.5\n"
    "  cy: 239.5\n"
    "  dist: [-0.05, 0.01, 0.0, 0.0, 0.0]\n"
    "  rate_hz: 10\n"
    "  phase_s: 0.013\n"
    "  supersample: 2\n"
    "  moving_supersample: 1\n";
const char* const kOneExtrinsic =
    "extrinsic:\n"
    "  xyz_m: [0.0295, 0.1218, -0.0458]\n"
    "  rpy_deg: [-125.8556, -87.5002, -143.1182]\n";

// The same camera as the entry `a` of a cameras: list, and a second one, `b`, looking left at a lower
// resolution, with its own model parameters, rate and phase.
const char* const kTwoCameras =
    "cameras:\n"
    "  - name: a\n"
    "    model: pinhole\n"
    "    width: 640\n"
    "    height: 480\n"
    "    fx: 320.0\n"
    "    fy: 320.0\n"
    "    cx: 319.5\n"
    "    cy: 239.5\n"
    "    dist: [-0.05, 0.01, 0.0, 0.0, 0.0]\n"
    "    rate_hz: 10\n"
    "    phase_s: 0.013\n"
    "    supersample: 2\n"
    "    moving_supersample: 1\n"
    "    extrinsic:\n"
    "      xyz_m: [0.0295, 0.1218, -0.0458]\n"
    "      rpy_deg: [-125.8556, -87.5002, -143.1182]\n"
    "  - name: Side_2\n"
    "    model: pinhole\n"
    "    width: 320\n"
    "    height: 240\n"
    "    fx: 161.0\n"
    "    fy: 160.0\n"
    "    cx: 160.5\n"
    "    cy: 119.0\n"
    "    rate_hz: 7.5\n"
    "    phase_s: 0.071\n"
    "    extrinsic:\n"
    "      xyz_m: [0.0, 0.1, -0.05]\n"
    "      rpy_deg: [90.0, 0.0, 0.0]\n";

class SimRig : public ::testing::Test {
 protected:
  const std::string one_ = ReadFile(testing::ScenarioPath("tiny-pinhole.yaml"));
  // tiny-pinhole.yaml with the two cameras of kTwoCameras.
  const std::string two_ = Replace(Replace(one_, kOneCamera, kTwoCameras), kOneExtrinsic, "");
};

TEST_F(SimRig, CamerasListParses) {
  const Scenario one = ParseScenario(one_);
  ASSERT_EQ(one.cameras.size(), 1u);
  EXPECT_EQ(one.cameras[0].name, "");
  EXPECT_EQ(&one.camera(), &one.cameras[0].settings);

  const Scenario s = ParseScenario(two_);
  ASSERT_EQ(s.cameras.size(), 2u);
  EXPECT_EQ(s.cameras[0].name, "a");
  EXPECT_EQ(s.cameras[1].name, "Side_2");
  EXPECT_EQ(s.CameraIndex("Side_2"), 1);
  EXPECT_EQ(s.CameraIndex("side_2"), -1);
  EXPECT_EQ(s.camera().params.width, 640);
  EXPECT_TRUE(s.T_camera_lidar().isApprox(one.T_camera_lidar(), 0.0));
  const CameraSettings& b = s.cameras[1].settings;
  EXPECT_EQ(b.params.width, 320);
  EXPECT_EQ(b.params.height, 240);
  EXPECT_DOUBLE_EQ(b.params.fx, 161.0);
  EXPECT_DOUBLE_EQ(b.params.cy, 119.0);
  EXPECT_DOUBLE_EQ(b.rate_hz, 7.5);
  EXPECT_DOUBLE_EQ(b.phase_s, 0.071);
  EXPECT_EQ(b.supersample, CameraSettings().supersample);  // defaults as in camera:
  EXPECT_TRUE(s.cameras[1].T_camera_lidar.isApprox(
      MakeIsometry(RotationFromRpy(M_PI / 2, 0, 0), Eigen::Vector3d(0.0, 0.1, -0.05)), 1e-12));

  // extrinsic_changes name their camera; the first camera by default.
  const Scenario c = ParseScenario(two_ +
                                   "extrinsic_changes:\n"
                                   "  - {after_stop: 2, delta_rpy_deg: [1, 0, 0], delta_xyz_m: [0, 0, 0]}\n"
                                   "  - {after_stop: 1, delta_rpy_deg: [0, 1, 0], delta_xyz_m: [0, 0, 0], "
                                   "camera: Side_2}\n"
                                   "  - {after_stop: 2, delta_rpy_deg: [0, 0, 1], delta_xyz_m: [0, 0, 0], "
                                   "camera: Side_2}\n");
  ASSERT_EQ(c.extrinsic_changes.size(), 3u);
  EXPECT_EQ(c.extrinsic_changes[0].camera, 0);
  EXPECT_EQ(c.extrinsic_changes[1].camera, 1);
  EXPECT_EQ(c.extrinsic_changes[2].camera, 1);
  EXPECT_EQ(ParseScenario(one_ + "extrinsic_changes:\n  - {after_stop: 1, delta_rpy_deg: [1, 0, 0], "
                                 "delta_xyz_m: [0, 0, 0]}\n")
                .extrinsic_changes[0]
                .camera,
            0);
}

TEST_F(SimRig, BadCamerasNameTheEntry) {
  // Exactly one of camera: and cameras:; extrinsic: goes with camera: only.
  ExpectErrorNaming(kOneCamera + two_, "cameras");
  ExpectErrorNaming(Replace(Replace(one_, kOneCamera, ""), kOneExtrinsic, ""), "camera");
  ExpectErrorNaming(Replace(one_, kOneExtrinsic, ""), "extrinsic");
  ExpectErrorNaming(two_ + kOneExtrinsic, "extrinsic");
  ExpectErrorNaming(Replace(Replace(one_, kOneCamera, "cameras: []\n"), kOneExtrinsic, ""), "cameras");
  ExpectErrorNaming(Replace(Replace(one_, kOneCamera, "cameras: {name: a}\n"), kOneExtrinsic, ""), "cameras");
  // Names: 1-32 characters of [A-Za-z0-9_], a letter first, unique.
  for (const char* name : {"2nd", "_side", "side-2", "side 2", "\"\"", "abcdefghijklmnopqrstuvwxyz0123456"})
    ExpectErrorNaming(Replace(two_, "name: Side_2", std::string("name: ") + name), "cameras[1].name");
  EXPECT_NO_THROW(ParseScenario(Replace(two_, "name: Side_2", "name: abcdefghijklmnopqrstuvwxyz012345")));
  ExpectErrorNaming(Replace(two_, "name: Side_2", "name: a"), "cameras[1].name");
  ExpectErrorNaming(Replace(two_, "  - name: Side_2\n", "  - model_name: Side_2\n"), "cameras[1].name");
  // Every camera key validated as in camera:.
  ExpectErrorNaming(Replace(two_, "    fx: 161.0\n", "    fx: -161.0\n"), "cameras[1].fx");
  ExpectErrorNaming(Replace(two_, "    fx: 161.0\n", ""), "cameras[1].fx");
  ExpectErrorNaming(Replace(two_, "    width: 320\n", "    width: 320\n    exposure_ms: 3\n"),
                    "cameras[1].exposure_ms");
  ExpectErrorNaming(Replace(two_, "    rate_hz: 7.5\n", "    rate_hz: 0\n"), "cameras[1].rate_hz");
  ExpectErrorNaming(Replace(two_, "    width: 320\n", "    width: 2000000000\n"), "cameras[1].width");
  ExpectErrorNaming(Replace(two_, "    model: pinhole\n    width: 320", "    model: fisheye\n    width: 320"),
                    "cameras[1].model");
  ExpectErrorNaming(Replace(two_, "      xyz_m: [0.0, 0.1, -0.05]\n", "      xyz_m: [0.0, 0.1]\n"),
                    "cameras[1].extrinsic.xyz_m");
  ExpectErrorNaming(
      Replace(two_, "    extrinsic:\n      xyz_m: [0.0, 0.1, -0.05]\n      rpy_deg: [90.0, 0.0, 0.0]\n", ""),
      "cameras[1].extrinsic");
  // extrinsic_changes[k].camera names a camera; each camera's changes in order of their stops.
  const auto change = [](const std::string& entries) { return "extrinsic_changes:\n" + entries; };
  ExpectErrorNaming(two_ + change("  - {after_stop: 1, delta_rpy_deg: [1, 0, 0], delta_xyz_m: [0, 0, 0], camera: c}\n"),
                    "extrinsic_changes[0].camera");
  ExpectErrorNaming(
      one_ + change("  - {after_stop: 1, delta_rpy_deg: [1, 0, 0], delta_xyz_m: [0, 0, 0], camera: front}\n"),
      "extrinsic_changes[0].camera");
  ExpectErrorNaming(
      two_ + change("  - {after_stop: 2, delta_rpy_deg: [1, 0, 0], delta_xyz_m: [0, 0, 0], camera: Side_2}\n"
                    "  - {after_stop: 1, delta_rpy_deg: [1, 0, 0], delta_xyz_m: [0, 0, 0]}\n"
                    "  - {after_stop: 2, delta_rpy_deg: [1, 0, 0], delta_xyz_m: [0, 0, 0], camera: Side_2}\n"),
      "extrinsic_changes[2].after_stop");
  // The session's frames count every camera's.
  ExpectErrorNaming(Replace(two_, "    rate_hz: 7.5\n", "    rate_hz: 1.0e7\n"), "motions");
}

// A two-camera simulation: each camera's frames at its own times (phase + k / rate), its own size, in
// one time-ordered event stream; random access gives the same bytes; the cameras' noise differs.
TEST_F(SimRig, EachCameraHasItsOwnFramesInOneTimeOrderedStream) {
  const Scenario s = ParseScenario(two_);
  Simulation sim(s), other(s, DefaultTextureDir(), 1);
  ASSERT_EQ(sim.num_cameras(), 2);
  EXPECT_EQ(sim.camera_name(1), "Side_2");
  EXPECT_EQ(sim.camera(1).width(), 320);
  const double duration = sim.trajectory().duration();
  for (int i = 0; i < 2; ++i) {
    const CameraSettings& c = s.cameras[i].settings;
    const auto& times = sim.camera_times(i);
    EXPECT_EQ(sim.num_camera_frames(i), static_cast<int>(times.size()));
    EXPECT_EQ(static_cast<int>(times.size()), static_cast<int>(std::floor((duration - c.phase_s) * c.rate_hz)) + 1);
    for (size_t k = 0; k < times.size(); ++k) EXPECT_EQ(times[k], std::llround((c.phase_s + k / c.rate_hz) * 1e6));
  }
  EXPECT_EQ(sim.num_events(), sim.camera_times(0).size() + sim.camera_times(1).size() + sim.lidar_times().size());

  std::vector<std::vector<cv::Mat>> images(2);
  Event e;
  int64_t last_utime = 0;
  while (sim.Next(&e)) {
    EXPECT_GE(e.utime, last_utime);
    last_utime = e.utime;
    if (e.type != Event::Type::kCamera) continue;
    const int i = e.camera.camera;
    ASSERT_TRUE(i == 0 || i == 1);
    ASSERT_EQ(e.camera.index, static_cast<int>(images[i].size())) << "camera " << i;
    EXPECT_EQ(e.camera.utime, s.start_utime + sim.camera_times(i)[e.camera.index]);
    EXPECT_EQ(e.camera.image.cols, i == 0 ? 640 : 320);
    EXPECT_EQ(e.camera.station_id, sim.trajectory().StillStation(sim.ToSeconds(e.utime), sim.ToSeconds(e.utime)));
    EXPECT_TRUE(e.camera.T_world_camera.isApprox(sim.T_world_camera(i, sim.ToSeconds(e.utime)), 1e-9));
    images[i].push_back(e.camera.image);
  }
  ASSERT_EQ(images[0].size(), sim.camera_times(0).size());
  ASSERT_EQ(images[1].size(), sim.camera_times(1).size());
  // Out of order, with the other camera's frames in between (each camera its own still-image cache).
  for (auto [i, k] : std::vector<std::pair<int, int>>{{1, 20}, {0, 3}, {1, 2}, {0, 60}, {1, 21}, {0, 4}}) {
    const CameraFrame f = other.RenderCameraFrame(i, k);
    EXPECT_EQ(f.camera, i);
    EXPECT_TRUE(SameBytes(f.image, images[i][k])) << "camera " << i << " frame " << k;
  }
  // The same station seen by both: camera 1 draws its own noise (not camera 0's, resized).
  const CameraFrame a = other.RenderCameraFrame(0, 2), b = other.RenderCameraFrame(1, 2);
  ASSERT_EQ(a.station_id, 0);
  ASSERT_EQ(b.station_id, 0);
  cv::Mat a_small;
  cv::resize(a.image, a_small, b.image.size(), 0, 0, cv::INTER_AREA);
  EXPECT_FALSE(SameBytes(a_small, b.image));
  // Stations: each camera's pose.
  for (const Station& st : sim.Stations()) {
    ASSERT_EQ(st.T_world_cameras.size(), 2u);
    EXPECT_TRUE(st.T_world_cameras[0].isApprox(st.T_world_camera, 0.0));
    EXPECT_TRUE(st.T_world_cameras[1].isApprox(st.T_world_lidar * s.cameras[1].T_camera_lidar.inverse(), 1e-12));
  }
}

// Camera 0 of a rig renders the bytes of the same camera alone: its seeds do not depend on the other
// cameras, nor on being given as a cameras: entry.
TEST_F(SimRig, OtherCamerasLeaveCameraZeroUnchanged) {
  Simulation alone(ParseScenario(one_)), rig(ParseScenario(two_));
  ASSERT_EQ(alone.camera_times(), rig.camera_times(0));
  for (int k : {2, 25, 40, 41})
    EXPECT_TRUE(SameBytes(alone.RenderCameraFrame(k).image, rig.RenderCameraFrame(0, k).image)) << "frame " << k;
  EXPECT_TRUE(alone.RenderCameraFrame(2).T_world_camera.isApprox(rig.RenderCameraFrame(0, 2).T_world_camera, 0.0));
}

// A one-camera scenario's frames are still those of the single-camera simulation: the noiseless render
// (the still one at camera.supersample, the moving one at camera.moving_scale, resized up) plus the
// gain and noise of MixSeed(MixSeed(seed, 1), k).
TEST_F(SimRig, OneCameraFramesAreTheSingleCameraOnes) {
  for (const char* file : {"tiny-pinhole.yaml", "tiny-equirect.yaml"}) {
    SCOPED_TRACE(file);
    const Scenario s = LoadScenario(testing::ScenarioPath(file));
    Simulation sim(s);
    ASSERT_EQ(sim.num_cameras(), 1);
    const Scene scene = BuildScene(s);
    const Trajectory trajectory = BuildTrajectory(s);
    const auto camera = MakeCameraModel(s.camera().params);
    const auto moving = MakeCameraModel(ScaleCamera(s.camera().params, s.camera().moving_scale));
    const CameraRays still_rays(*camera, s.camera().supersample), moving_rays(*moving, s.camera().moving_supersample);
    int still = 0, in_motion = 0;
    for (int k : {0, 1, 25, 31, 40, 55}) {
      const CameraFrame f = sim.RenderCameraFrame(k);
      const double t = sim.camera_times()[k] * 1e-6;
      const Isometry3 T_world_camera = trajectory.T_world_lidar(t) * s.T_camera_lidar().inverse();
      EXPECT_EQ(f.utime, s.start_utime + std::llround((s.camera().phase_s + k / s.camera().rate_hz) * 1e6));
      EXPECT_TRUE(f.T_world_camera.isApprox(T_world_camera, 0.0));
      cv::Mat clean;
      if (f.station_id >= 0) {
        ++still;
        clean = RenderClean(scene, still_rays, T_world_camera, s.camera().color);
      } else {
        ++in_motion;
        clean = RenderClean(scene, moving_rays, T_world_camera, s.camera().color);
        cv::resize(clean, clean, cv::Size(camera->width(), camera->height()), 0, 0, cv::INTER_LINEAR);
      }
      const uint64_t seed = MixSeed(MixSeed(s.seed, 1), static_cast<uint64_t>(k));
      Rng rng(MixSeed(seed, 0xE));
      const double gain = std::exp(s.noise.exposure_sigma * rng.Gaussian());
      EXPECT_TRUE(SameBytes(f.image, ApplyImageNoise(clean, gain, s.noise.image_sigma, seed))) << "frame " << k;
    }
    EXPECT_GE(still, 2);
    EXPECT_GE(in_motion, 2);
  }
}

// An extrinsic change applies to the camera it names only: its images from the change on are those of a
// rig with its new extrinsic from the start; the other camera's are unchanged.
TEST_F(SimRig, ExtrinsicChangeAppliesToTheNamedCameraOnly) {
  const std::string changed = two_ +
                              "extrinsic_changes:\n"
                              "  - {after_stop: 1, delta_rpy_deg: [2, 0, 0], delta_xyz_m: [0.03, 0, 0], "
                              "camera: Side_2}\n";
  const Scenario s = ParseScenario(changed);
  Simulation sim(s), unchanged(ParseScenario(two_));
  ASSERT_EQ(sim.extrinsics(0).size(), 1u);
  ASSERT_EQ(sim.extrinsics(1).size(), 2u);
  const ExtrinsicEpoch& epoch = sim.extrinsics(1)[1];
  EXPECT_EQ(epoch.camera, 1);
  EXPECT_EQ(epoch.after_stop, 1);
  EXPECT_TRUE(epoch.T_camera_lidar.isApprox(s.cameras[1].T_camera_lidar * s.extrinsic_changes[0].delta, 1e-12));
  EXPECT_TRUE(sim.T_camera_lidar_at(1, epoch.from_utime - 1).isApprox(s.cameras[1].T_camera_lidar, 0.0));
  EXPECT_TRUE(sim.T_camera_lidar_at(1, epoch.from_utime).isApprox(epoch.T_camera_lidar, 0.0));
  EXPECT_TRUE(sim.T_camera_lidar_at(0, epoch.from_utime + 1000000).isApprox(s.T_camera_lidar(), 0.0));
  const auto stations = sim.Stations();
  EXPECT_TRUE(stations[0].T_world_cameras[1].isApprox(unchanged.Stations()[0].T_world_cameras[1], 0.0));
  EXPECT_TRUE(
      stations[1].T_world_cameras[1].isApprox(stations[1].T_world_lidar * epoch.T_camera_lidar.inverse(), 1e-12));
  EXPECT_TRUE(stations[1].T_world_camera.isApprox(unchanged.Stations()[1].T_world_camera, 0.0));

  Scenario moved = ParseScenario(two_);
  moved.cameras[1].T_camera_lidar = epoch.T_camera_lidar;
  Simulation after(moved);
  const auto first_after = [&](int i) {
    const auto& times = sim.camera_times(i);
    return static_cast<int>(std::lower_bound(times.begin(), times.end(), epoch.from_utime - s.start_utime) -
                            times.begin());
  };
  for (int k : {first_after(0) - 1, first_after(0), first_after(0) + 20})
    EXPECT_TRUE(SameBytes(sim.RenderCameraFrame(0, k).image, unchanged.RenderCameraFrame(0, k).image)) << k;
  const int b = first_after(1);
  EXPECT_TRUE(SameBytes(sim.RenderCameraFrame(1, b - 1).image, unchanged.RenderCameraFrame(1, b - 1).image));
  for (int k : {b, b + 15}) {
    const CameraFrame f = sim.RenderCameraFrame(1, k);
    EXPECT_TRUE(SameBytes(f.image, after.RenderCameraFrame(1, k).image)) << k;
    EXPECT_FALSE(SameBytes(f.image, unchanged.RenderCameraFrame(1, k).image)) << k;
  }
}

struct RigExpectation {
  const char* file;
  std::map<std::string, Eigen::Vector3d> facing;  // each camera's optical axis, LiDAR frame
};

// The shipped rigs: cameras facing their ways, 10-20 cm from the LiDAR; each camera's image agrees with
// the LiDAR's intensities under its own extrinsic, and it sees texture at every station.
TEST(SimRigScenarios, ShippedRigsLookTheirWayAndSeeTexture) {
  const std::vector<RigExpectation> rigs = {
      {"ring4-pinhole-hdl64.yaml",
       {{"front", {1, 0, 0}}, {"left", {0, 1, 0}}, {"rear", {-1, 0, 0}}, {"right", {0, -1, 0}}}},
      {"stereo-pinhole-hdl64.yaml", {{"left", {1, 0, 0}}, {"right", {1, 0, 0}}}}};
  for (const RigExpectation& rig : rigs) {
    SCOPED_TRACE(rig.file);
    const Scenario s = LoadScenario(testing::ScenarioPath(rig.file));
    ASSERT_EQ(s.cameras.size(), rig.facing.size());
    for (const RigCamera& c : s.cameras) {
      SCOPED_TRACE(c.name);
      ASSERT_TRUE(rig.facing.count(c.name));
      const Eigen::Vector3d axis = c.T_camera_lidar.linear().transpose() * Eigen::Vector3d::UnitZ();
      EXPECT_GT(axis.dot(rig.facing.at(c.name)), std::cos(3.0 * M_PI / 180));
      const double distance = c.T_camera_lidar.inverse().translation().norm();
      EXPECT_GT(distance, 0.10);
      EXPECT_LT(distance, 0.20);
    }
    if (std::string(rig.file) == "stereo-pinhole-hdl64.yaml") {
      const Eigen::Vector3d baseline =
          s.cameras[0].T_camera_lidar.inverse().translation() - s.cameras[1].T_camera_lidar.inverse().translation();
      EXPECT_NEAR(baseline.norm(), 0.12, 0.005);
      EXPECT_GT(baseline.y(), 0.11);  // left is left
    }

    Simulation sim(s);
    const auto stations = sim.Stations();
    const SimulatedScan scan = ScanLidar(sim.scene(), s.lidar, stations[0].T_world_lidar, 200);
    for (int i = 0; i < sim.num_cameras(); ++i) {
      SCOPED_TRACE(s.cameras[i].name);
      for (const Station& st : stations) {
        const auto& times = sim.camera_times(i);
        const int64_t middle = (st.still_from_utime + st.still_to_utime) / 2 - s.start_utime;
        const int k = static_cast<int>(std::lower_bound(times.begin(), times.end(), middle) - times.begin());
        const CameraFrame f = sim.RenderCameraFrame(i, k);
        ASSERT_EQ(f.station_id, st.id);
        // Corners in every quarter of the image: texture, not a blank wall.
        std::vector<cv::Point2f> corners;
        cv::goodFeaturesToTrack(f.image, corners, 2000, 0.02, 8);
        int quarters[4] = {0, 0, 0, 0};
        for (const auto& p : corners) ++quarters[(p.x >= f.image.cols / 2) + 2 * (p.y >= f.image.rows / 2)];
        for (int q = 0; q < 4; ++q) EXPECT_GE(quarters[q], 100) << "station " << st.id << ", quarter " << q;
        if (st.id != 0) continue;
        size_t used = 0;
        const double truth = testing::IntensityCorrelation(scan, f.image, sim.camera(i), sim.T_camera_lidar(i), &used);
        EXPECT_GT(used, 5000u);
        EXPECT_GT(truth, 0.7);
        Isometry3 rotated = sim.T_camera_lidar(i);
        rotated.prerotate(Eigen::AngleAxisd(M_PI / 180.0, Eigen::Vector3d::UnitX()));
        EXPECT_LT(testing::IntensityCorrelation(scan, f.image, sim.camera(i), rotated), truth - 0.1);
      }
    }
  }
}

}  // namespace
}  // namespace fusecal::sim
