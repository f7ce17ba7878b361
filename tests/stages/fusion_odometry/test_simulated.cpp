// Fusion odometry on simulated stop-and-rotate recordings (runtime/sim/simulator): with the true extrinsic the
// metric camera motion of every motion is within 5 mm and 0.05 deg of the truth; with a perturbed extrinsic
// the motion error grows smoothly with the perturbation, not catastrophically.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "runtime/sim/fixtures/fo_test_data.hpp"
#include "stages/fusion_odometry/fusion_odometry.hpp"

namespace fusecal::fusion_odometry {
namespace {

using fixtures::Deg;
using fixtures::SimData;

struct MotionError {
  double rotation_deg = 0;
  double translation_m = 0;
};

MotionError Error(const Isometry3& estimate, const Isometry3& truth) {
  return {RotationErrorDeg(estimate.linear(), truth.linear()), (estimate.translation() - truth.translation()).norm()};
}

// Runs motion s -> s+1: first iteration (rough guess X0 B X0^-1, not reliable: P3P RANSAC), then the next
// iteration (the estimate as a reliable guess), with `extrinsic` as the current X.
struct MotionRun {
  FusionOdometryResult first, next;
  MotionError first_error, next_error;
};

MotionRun RunMotion(const SimData& data, size_t s, const Isometry3& extrinsic,
                    const FusionOdometrySettings& settings = {}) {
  const auto& i = data.stations[s];
  const auto& j = data.stations[s + 1];
  const Isometry3 A_true = fixtures::TrueCameraMotion(i, j);
  const Isometry3 B_true = fixtures::TrueLidarMotion(i, j);
  // The rough initial extrinsic the hand-eye initialisation might give: 3 cm and 2 deg off.
  const Isometry3 X_rough = fixtures::PerturbExtrinsic(data.T_camera_lidar, 0.03, 2.0);
  MotionRun run;
  run.first = EstimateScaledMotion(i.scan, i.image, j.image, *data.camera, extrinsic,
                                   MotionGuess{CameraMotionFromLidar(X_rough, B_true), false}, settings);
  run.next = EstimateScaledMotion(i.scan, i.image, j.image, *data.camera, extrinsic,
                                  MotionGuess{run.first.T_ci_cj, true}, settings);
  run.first_error = Error(run.first.T_ci_cj, A_true);
  run.next_error = Error(run.next.T_ci_cj, A_true);
  std::printf(
      "  motion %d -> %d (%5.1f deg, %.3f m): first %.4f deg %.2f mm (%d inliers, ransac %d), "
      "next %.4f deg %.2f mm (%d inliers), %.3f s\n",
      i.id, j.id, Deg(RotationAngle(A_true.linear())), A_true.translation().norm(), run.first_error.rotation_deg,
      1e3 * run.first_error.translation_m, run.first.inliers, run.first.used_ransac, run.next_error.rotation_deg,
      1e3 * run.next_error.translation_m, run.next.inliers, run.first.seconds);
  return run;
}

class SimulatedTiny : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    data_ = new SimData(fixtures::SimulateStations(sim::LoadScenario(fixtures::ScenarioPath("tiny-equirect.yaml"))));
  }
  static void TearDownTestSuite() {
    delete data_;
    data_ = nullptr;
  }
  static SimData* data_;
};
SimData* SimulatedTiny::data_ = nullptr;

TEST_F(SimulatedTiny, TrueExtrinsicGivesMotionsWithin5mmAnd005deg) {
  ASSERT_GE(data_->stations.size(), 5u) << "tiny-equirect has 2 turns and 2 tilts";
  for (size_t s = 0; s + 1 < data_->stations.size(); ++s) {
    const MotionRun run = RunMotion(*data_, s, data_->T_camera_lidar);
    for (const FusionOdometryResult* r : {&run.first, &run.next}) {
      ASSERT_TRUE(r->usable()) << r->failure_reason;
      EXPECT_EQ(r->status, status::kConverged);
      EXPECT_EQ(r->failure_reason.code, FusionOdometryFailure::kNone);
      EXPECT_TRUE(r->failure_reason.text.empty());
      EXPECT_GE(r->inliers, 100);
      EXPECT_TRUE(r->covariance_valid);
    }
    EXPECT_TRUE(run.first.used_ransac);
    EXPECT_FALSE(run.next.used_ransac) << "a reliable guess that explains the tracks needs no RANSAC";
    for (const MotionError& e : {run.first_error, run.next_error}) {
      EXPECT_LE(e.rotation_deg, 0.05) << "motion " << s;
      EXPECT_LE(e.translation_m, 0.005) << "motion " << s;
    }
    // The covariance is in the right order of magnitude: the true error is within 5 sigma of each axis
    // block (rotation and translation, as a whole).
    const Matrix6& C = run.first.covariance;
    EXPECT_GT(C(0, 0), 0.0);
    EXPECT_LT(run.first_error.translation_m, 5.0 * std::sqrt(C.bottomRightCorner<3, 3>().trace()) + 1e-3);
  }
}

// The extrinsic moved by growing amounts (the calibration loop starts from a wrong X). A wrong X starts
// each track at the pixel where X' projects the point, and pairs the texture there with X' p: the ray
// from camera i stays right, only the depth along it is off (by about the extrinsic's translation and the
// surface slope times the pixel shift). So the motion error must stay bounded, without jumps, and grow at
// most slowly; with a panorama the depth errors of all directions largely cancel and it hardly grows.
void CheckPerturbationCurve(const SimData& data, const char* name, bool expect_growth) {
  const std::vector<std::pair<double, double>> perturbations = {
      {0.0, 0.0}, {0.01, 0.2}, {0.025, 0.5}, {0.05, 1.0}, {0.1, 2.0}};
  std::vector<double> rotation_deg, translation_mm;
  for (const auto& [dt, dr] : perturbations) {
    const Isometry3 X = fixtures::PerturbExtrinsic(data.T_camera_lidar, dt, dr);
    double rot = 0, trans = 0;
    int n = 0;
    std::printf(" %s, extrinsic off by %.3f m, %.2f deg:\n", name, dt, dr);
    for (size_t s = 0; s + 1 < data.stations.size(); ++s) {
      const MotionRun run = RunMotion(data, s, X);
      ASSERT_TRUE(run.first.usable()) << run.first.failure_reason;
      ASSERT_TRUE(run.next.usable()) << run.next.failure_reason;
      rot += run.next_error.rotation_deg;
      trans += 1e3 * run.next_error.translation_m;
      ++n;
    }
    rotation_deg.push_back(rot / n);
    translation_mm.push_back(trans / n);
  }
  std::printf(" %s: extrinsic perturbation -> mean motion error:\n", name);
  for (size_t k = 0; k < perturbations.size(); ++k)
    std::printf("   %5.3f m %4.2f deg -> %.4f deg, %.2f mm\n", perturbations[k].first, perturbations[k].second,
                rotation_deg[k], translation_mm[k]);
  for (size_t k = 1; k < perturbations.size(); ++k) {
    // Smooth: each step adds at most a fifth of the added perturbation (plus noise).
    const double step_mm = 1e3 * (perturbations[k].first - perturbations[k - 1].first);
    const double step_deg = perturbations[k].second - perturbations[k - 1].second;
    EXPECT_LE(translation_mm[k] - translation_mm[k - 1], 0.2 * step_mm + 1.0) << name << ", step " << k;
    EXPECT_LE(rotation_deg[k] - rotation_deg[k - 1], 0.2 * step_deg + 0.01) << name << ", step " << k;
    // Roughly monotonic: never clearly better with a worse extrinsic.
    EXPECT_GE(translation_mm[k], 0.5 * translation_mm[k - 1] - 1.0) << name << ", step " << k;
    EXPECT_GE(rotation_deg[k], 0.5 * rotation_deg[k - 1] - 0.01) << name << ", step " << k;
  }
  // Bounded at 5 cm / 1 deg: well below the extrinsic error itself.
  EXPECT_LT(translation_mm[3], 15.0) << name;
  EXPECT_LT(rotation_deg[3], 0.2) << name;
  if (expect_growth) {  // a pinhole sees one side only: the depth errors do not cancel
    EXPECT_GT(translation_mm.back(), translation_mm.front()) << name;
    EXPECT_GT(rotation_deg.back(), rotation_deg.front()) << name;
  }
}

TEST_F(SimulatedTiny, MotionErrorGrowsSmoothlyWithExtrinsicError) {
  CheckPerturbationCurve(*data_, "tiny-equirect", /*expect_growth=*/false);
}

// The paper's pinhole case: indoor-pinhole-hdl64 with the image and the LiDAR reduced (640x360, 32 beams)
// and fewer motions, to keep the test fast.
std::string ReducedPinholeScenario() {
  std::ifstream in(fixtures::ScenarioPath("indoor-pinhole-hdl64.yaml"));
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  auto replace = [&](const std::string& from, const std::string& to) {
    const size_t at = yaml.find(from);
    if (at == std::string::npos) throw std::runtime_error("scenario text changed: '" + from + "' not found");
    yaml.replace(at, from.size(), to);
  };
  replace("width: 1280", "width: 640");
  replace("height: 720", "height: 360");
  replace("fx: 640.0", "fx: 320.0");
  replace("fy: 640.0", "fy: 320.0");
  replace("cx: 639.5", "cx: 319.5");
  replace("cy: 359.5", "cy: 179.5");
  replace("beams: 64", "beams: 32");
  replace("azimuth_resolution_deg: 0.18", "azimuth_resolution_deg: 0.36");
  replace("horizontal: 5", "horizontal: 2");
  replace("vertical: 5", "vertical: 2");
  replace("still_s: 3.0", "still_s: 1.0");
  replace("move_s: [2.0, 3.0]", "move_s: [1.0, 1.5]");
  return yaml;
}

class SimulatedPinhole : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    data_ = new SimData(fixtures::SimulateStations(sim::ParseScenario(ReducedPinholeScenario())));
    std::printf(" reduced pinhole scenario: %zu stations, rendered in %.1f s\n", data_->stations.size(),
                data_->seconds_render);
  }
  static void TearDownTestSuite() {
    delete data_;
    data_ = nullptr;
  }
  static SimData* data_;
};
SimData* SimulatedPinhole::data_ = nullptr;

TEST_F(SimulatedPinhole, TrueExtrinsicGivesMotionsWithin5mmAnd005deg) {
  const SimData& data = *data_;
  ASSERT_GE(data.stations.size(), 5u);
  for (size_t s = 0; s + 1 < data.stations.size(); ++s) {
    const MotionRun run = RunMotion(data, s, data.T_camera_lidar);
    for (const FusionOdometryResult* r : {&run.first, &run.next}) {
      ASSERT_TRUE(r->usable()) << r->failure_reason;
      EXPECT_GE(r->inliers, 50);
    }
    for (const MotionError& e : {run.first_error, run.next_error}) {
      EXPECT_LE(e.rotation_deg, 0.05) << "motion " << s;
      EXPECT_LE(e.translation_m, 0.005) << "motion " << s;
    }
  }
}

TEST_F(SimulatedPinhole, MotionErrorGrowsSmoothlyWithExtrinsicError) {
  CheckPerturbationCurve(*data_, "reduced pinhole", /*expect_growth=*/true);
}

}  // namespace
}  // namespace fusecal::fusion_odometry
