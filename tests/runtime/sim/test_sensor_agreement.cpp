// Camera and LiDAR see the same world: with the true extrinsic, LiDAR intensity and image grey value at
// the projected points agree; a 1 degree or 5 cm error in the extrinsic visibly breaks the agreement.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "runtime/sim/simulator/render.hpp"
#include "runtime/sim/simulator/trajectory.hpp"
#include "tests/support/simulator_test_util.hpp"

namespace fusecal::sim {
namespace {

struct Correlations {
  double truth;
  std::vector<double> perturbed;  // each perturbation
};

// Renders station `station` of a scenario and correlates the scan with the image under the true and
// perturbed extrinsics (1 deg about each camera axis, 5 cm along each).
Correlations Measure(const std::string& scenario_file, int station) {
  const Scenario s = LoadScenario(testing::ScenarioPath(scenario_file));
  const Scene scene = BuildScene(s);
  const auto camera = MakeCameraModel(s.camera().params);
  const Isometry3 T_world_lidar = BuildTrajectory(s).stills().at(station).T_world_lidar;
  RenderOptions o;
  o.supersample = s.camera().supersample;
  o.noise_sigma = s.noise.image_sigma;
  const cv::Mat image = RenderImage(scene, *camera, T_world_lidar * s.T_camera_lidar().inverse(), o, 100);
  const SimulatedScan scan = ScanLidar(scene, s.lidar, T_world_lidar, 200);

  Correlations c;
  size_t used = 0;
  c.truth = testing::IntensityCorrelation(scan, image, *camera, s.T_camera_lidar(), &used);
  EXPECT_GT(used, 10000u);
  for (int axis = 0; axis < 3; ++axis) {
    Isometry3 rotated = s.T_camera_lidar();
    rotated.prerotate(Eigen::AngleAxisd(M_PI / 180.0, Eigen::Vector3d::Unit(axis)));
    c.perturbed.push_back(testing::IntensityCorrelation(scan, image, *camera, rotated));
    Isometry3 shifted = s.T_camera_lidar();
    shifted.pretranslate(0.05 * Eigen::Vector3d::Unit(axis));
    c.perturbed.push_back(testing::IntensityCorrelation(scan, image, *camera, shifted));
  }
  return c;
}

void Record(const Correlations& c) {
  ::testing::Test::RecordProperty("correlation_truth", std::to_string(c.truth));
  std::string perturbed;
  for (double p : c.perturbed) perturbed += std::to_string(p) + " ";
  ::testing::Test::RecordProperty("correlation_perturbed", perturbed);
}

void ExpectAgreement(const Correlations& c) {
  EXPECT_GT(c.truth, 0.8);
  for (size_t i = 0; i < c.perturbed.size(); ++i) {
    SCOPED_TRACE(i % 2 == 0 ? "1 deg about camera axis " + std::to_string(i / 2)
                            : "5 cm along camera axis " + std::to_string(i / 2));
    EXPECT_LT(c.perturbed[i], c.truth - 0.1) << "truth " << c.truth << ", perturbed " << c.perturbed[i];
  }
}

TEST(SimSensorAgreement, EquirectangularIntensityMatchesImage) {
  const Correlations c = Measure("indoor-equirect-hdl64.yaml", 0);
  Record(c);
  ExpectAgreement(c);
}

TEST(SimSensorAgreement, PinholeIntensityMatchesImage) {
  // A tilted station, so the pinhole camera's view overlaps more beams.
  const Correlations c = Measure("indoor-pinhole-hdl64.yaml", 2);
  Record(c);
  ExpectAgreement(c);
}

TEST(SimSensorAgreement, ScanPointsLieOnTheRoom) {
  // Noise-free 64-beam scan: every point is inside the 10 x 8 x 3 m room, and the points that hit the
  // floor are at z = 0 to float precision.
  Scenario s = LoadScenario(testing::ScenarioPath("indoor-equirect-hdl64.yaml"));
  s.lidar.range_sigma_m = 0.0;
  s.lidar.dropout = 0.0;
  const Scene scene = BuildScene(s);
  const Isometry3 T = BuildTrajectory(s).stills().at(1).T_world_lidar;
  const SimulatedScan scan = ScanLidar(scene, s.lidar, T, 1);
  EXPECT_EQ(scan.points.size(), 64u * 2000u);  // closed room: every beam returns
  int floor = 0;
  for (const auto& p : scan.points) {
    const Eigen::Vector3d w = T * Eigen::Vector3d(p.x, p.y, p.z);
    ASSERT_LE(std::abs(w.x()), 5.0 + 1e-3);
    ASSERT_LE(std::abs(w.y()), 4.0 + 1e-3);
    ASSERT_GE(w.z(), -1e-3);
    ASSERT_LE(w.z(), 3.0 + 1e-3);
    if (std::abs(w.z()) < 1e-3) ++floor;
    ASSERT_GE(p.intensity, 0.0f);
    ASSERT_LE(p.intensity, 1.0f);
    ASSERT_LT(p.ring, 64);
    ASSERT_GE(p.time_offset_us, 0);
    ASSERT_LT(p.time_offset_us, 100000);
  }
  EXPECT_GT(floor, 20000);
}

TEST(SimSensorAgreement, MotionDistortionShiftsColumnsByTheirFiringTime) {
  // While turning, column c is taken at the pose of its own time: a point seen by the last columns
  // agrees with a scan at that later pose, not with one at the start pose.
  const Scenario s = LoadScenario(testing::ScenarioPath("tiny-equirect.yaml"));
  const Scene scene = BuildScene(s);
  LidarParams params = s.lidar;
  params.range_sigma_m = 0.0;
  params.dropout = 0.0;
  const LidarSensor lidar(params);
  const Trajectory tr = BuildTrajectory(s);
  const auto& m = tr.motions().at(0);
  const double t0 = 0.5 * (m.t_from + m.t_to) - 0.05;
  const CleanScan moving = lidar.CastClean(scene, [&](double dt) { return tr.T_world_lidar(t0 + dt); });
  const int c = lidar.columns() - 1;
  const CleanScan at_end = lidar.CastClean(scene, tr.T_world_lidar(t0 + lidar.ColumnTime(c)));
  const CleanScan at_start = lidar.CastClean(scene, tr.T_world_lidar(t0));
  double same_end = 0, same_start = 0;
  for (int b = 0; b < lidar.beams(); ++b) {
    const size_t k = static_cast<size_t>(c) * lidar.beams() + b;
    same_end += std::abs(moving.range[k] - at_end.range[k]);
    same_start += std::abs(moving.range[k] - at_start.range[k]);
  }
  EXPECT_LT(same_end, 1e-3);
  EXPECT_GT(same_start, 10 * same_end + 1e-3);
}

}  // namespace
}  // namespace fusecal::sim

namespace fusecal::sim {
namespace {

TEST(SimSensorAgreement, PanoramicScannerCoversTheSphere) {
  const std::string base = R"(
seed: 3
scene: indoor
camera: {model: equirectangular, width: 64, height: 32}
lidar: {model: panoramic, beams: 76, azimuth_resolution_deg: 2.0}
extrinsic: {xyz_m: [0, 0, 0], rpy_deg: [0, 0, 0]}
motions: {horizontal: 1, vertical: 1, rotation_deg: [10, 20]}
noise: {image_sigma: 0, lidar_range_sigma_m: 0}
)";
  const Scenario s = ParseScenario(base);
  EXPECT_EQ(s.lidar.model, "panoramic");
  const std::vector<double> el = s.lidar.ElevationsRad();  // panoramic default: +90 .. -60 deg
  EXPECT_NEAR(el.front(), M_PI / 2, 1e-12);
  EXPECT_NEAR(el.back(), -M_PI / 3, 1e-12);
  const Scene scene = BuildScene(s);
  const Isometry3 T = BuildTrajectory(s).stills()[0].T_world_lidar;
  const SimulatedScan scan = ScanLidar(scene, s.lidar, T, 1);
  EXPECT_EQ(scan.points.size(), 76u * 180u);  // closed room: every ray returns
  double max_z = -1;
  for (const auto& p : scan.points) max_z = std::max(max_z, (T * Eigen::Vector3d(p.x, p.y, p.z)).z());
  EXPECT_NEAR(max_z, 3.0, 0.05);  // straight up: the ceiling
}

}  // namespace
}  // namespace fusecal::sim
