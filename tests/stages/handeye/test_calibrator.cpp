// The calibration loop (III-B) without a bus: events in, versions out, with the faults a bus brings
// (motions late, twice, never, out of order; a stage that restarts).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

#include "stages/foundation/se3.hpp"
#include "stages/handeye/calibrator.hpp"
#include "stages/handeye/synthetic_motions.hpp"

namespace fusecal {
namespace {

constexpr int64_t kSecond = 1000000;

// Metric motion pairs of one rig; the camera front end gives their directions only, fusion odometry the
// metric camera motions it is asked for.
struct Rig {
  SyntheticMotionSet set;

  explicit Rig(int motions, uint32_t seed = 3) {
    SyntheticMotionSettings s;
    s.num_motions = motions;
    s.min_angle_deg = 10;
    s.max_angle_deg = 30;
    s.rotation_noise_deg = 0.02;
    s.translation_noise_m = 0.0005;
    s.seed = seed;
    set = GenerateSyntheticMotions(s);
  }
  SensorMotion Lidar(int k) const { return Motion(SensorMotion::Sensor::kLidar, k, set.pairs[k].B, false); }
  SensorMotion FrontEndCamera(int k) const {
    Isometry3 A = set.pairs[k].A;
    A.translation().normalize();
    return Motion(SensorMotion::Sensor::kCamera, k, A, false);
  }
  // What fusion odometry answers to a request: the metric camera motions of the pairs it lists.
  std::vector<SensorMotion> Fused(const CalibrationVersion& request) const {
    std::vector<SensorMotion> out;
    for (const auto& [i, j] : request.used)
      out.push_back(Motion(SensorMotion::Sensor::kCamera, i, set.pairs[i].A, true));
    return out;
  }

 private:
  SensorMotion Motion(SensorMotion::Sensor sensor, int k, const Isometry3& T, bool scaled) const {
    SensorMotion m;
    m.sensor = sensor;
    m.station_i = set.pairs[k].station_i;
    m.station_j = set.pairs[k].station_j;
    m.valid = true;
    m.scaled = scaled;
    m.T_i_j = T;
    return m;
  }
};

CalibratorSettings Settings() {
  CalibratorSettings s;
  s.retry_s = 3.0;
  return s;
}

// Answers every request until none is open; returns every version seen.
std::vector<CalibrationVersion> AnswerAll(Calibrator& calibrator, const Rig& rig,
                                          std::vector<CalibrationVersion> versions, int64_t now) {
  std::vector<CalibrationVersion> seen;
  while (!versions.empty()) {
    seen.insert(seen.end(), versions.begin(), versions.end());
    const CalibrationVersion& last = versions.back();
    versions =
        last.asks() ? calibrator.OnFusedMotions(last.version, rig.Fused(last), now) : std::vector<CalibrationVersion>{};
  }
  return seen;
}

// Pairs [0, n): each LiDAR motion, then its camera motion, every request answered.
void PlayPairs(Calibrator& calibrator, const Rig& rig, int n) {
  for (int k = 0; k < n; ++k) {
    calibrator.OnMotion(rig.Lidar(k), 0);
    AnswerAll(calibrator, rig, calibrator.OnMotion(rig.FrontEndCamera(k), 0), 0);
  }
}

double RotationError(const Calibrator& c, const Rig& rig) {
  return RotationErrorDeg(c.current()->T_camera_lidar.linear(), rig.set.T_camera_lidar.linear());
}
double TranslationError(const Calibrator& c, const Rig& rig) {
  return (c.current()->T_camera_lidar.translation() - rig.set.T_camera_lidar.translation()).norm();
}

TEST(Calibrator, AlternatesWithFusionOdometryUntilTheChangeIsSmall) {
  const Rig rig(12);
  Calibrator calibrator(Settings());
  std::vector<CalibrationVersion> all;
  for (int k = 0; k < 12; ++k) {
    EXPECT_TRUE(calibrator.OnMotion(rig.Lidar(k), 0).empty()) << "half a pair starts nothing";
    const auto seen = AnswerAll(calibrator, rig, calibrator.OnMotion(rig.FrontEndCamera(k), 0), 0);
    all.insert(all.end(), seen.begin(), seen.end());
  }
  ASSERT_TRUE(calibrator.converged()) << calibrator.state();
  EXPECT_EQ(calibrator.state(), "converged");
  EXPECT_TRUE(calibrator.current()->scaled);
  EXPECT_LT(RotationError(calibrator, rig), 0.1);
  EXPECT_LT(TranslationError(calibrator, rig), 0.01);
  EXPECT_EQ(calibrator.awaiting_version(), -1);
  for (size_t k = 0; k < all.size(); ++k) EXPECT_EQ(all[k].version, static_cast<int>(k) + 1);
  // The last round began with the scaleless record, then asked from the scaled estimate (resume).
  const auto initial = std::find_if(all.rbegin(), all.rend(),
                                    [](const CalibrationVersion& v) { return v.status == VersionStatus::kInitial; });
  ASSERT_NE(initial, all.rend());
  EXPECT_FALSE(initial->result.scaled);
  EXPECT_TRUE(all.back().converged());
  EXPECT_EQ(all.back().used.size() + all.back().not_used.size(), 12u) << "every held pair is listed";
}

// Fusion odometry whose answer flips with the request (even versions shift every camera translation by
// +offset, odd ones by -offset along x): the alternation cycles between two estimates.
std::vector<CalibrationVersion> AnswerFlipping(Calibrator& calibrator, const Rig& rig, double offset_m,
                                               std::vector<CalibrationVersion> versions) {
  std::vector<CalibrationVersion> seen;
  while (!versions.empty()) {
    seen.insert(seen.end(), versions.begin(), versions.end());
    const CalibrationVersion& last = versions.back();
    if (!last.asks()) break;
    std::vector<SensorMotion> fused = rig.Fused(last);
    for (SensorMotion& m : fused) m.T_i_j.translation().x() += last.version % 2 == 0 ? offset_m : -offset_m;
    versions = calibrator.OnFusedMotions(last.version, fused, 0);
  }
  return seen;
}

std::vector<CalibrationVersion> PlayFlipping(Calibrator& calibrator, const Rig& rig, double offset_m) {
  std::vector<CalibrationVersion> seen;
  for (int k = 0; k < 10; ++k) {
    calibrator.OnMotion(rig.Lidar(k), 0);
    const auto v = AnswerFlipping(calibrator, rig, offset_m, calibrator.OnMotion(rig.FrontEndCamera(k), 0));
    seen.insert(seen.end(), v.begin(), v.end());
  }
  return seen;
}

TEST(Calibrator, ACycleOfTwoEstimatesWithinTheirStdHasConverged) {
  const Rig rig(10);
  Calibrator calibrator(Settings());
  const auto seen = PlayFlipping(calibrator, rig, 0.0005);
  ASSERT_FALSE(seen.empty());
  EXPECT_TRUE(calibrator.converged()) << calibrator.state();
  EXPECT_LT(seen.back().iteration, Settings().max_iterations);
  EXPECT_NE(seen.back().result.message.find("settled into a cycle"), std::string::npos) << seen.back().result.message;
}

TEST(Calibrator, ACycleWiderThanTheStdIsNotConvergence) {
  const Rig rig(10);
  Calibrator calibrator(Settings());
  const auto seen = PlayFlipping(calibrator, rig, 0.02);
  ASSERT_FALSE(seen.empty());
  EXPECT_FALSE(calibrator.converged()) << calibrator.state();
  EXPECT_EQ(seen.back().status, VersionStatus::kNotConverged);
  EXPECT_EQ(seen.back().iteration, Settings().max_iterations);
}

TEST(Calibrator, AMotionOfEitherSensorMayComeFirst) {
  const Rig rig(8);
  Calibrator lidar_first(Settings()), camera_first(Settings());
  for (int k = 0; k < 8; ++k) {
    lidar_first.OnMotion(rig.Lidar(k), 0);
    AnswerAll(lidar_first, rig, lidar_first.OnMotion(rig.FrontEndCamera(k), 0), 0);
    camera_first.OnMotion(rig.FrontEndCamera(k), 0);
    AnswerAll(camera_first, rig, camera_first.OnMotion(rig.Lidar(k), 0), 0);
  }
  ASSERT_TRUE(lidar_first.current() && camera_first.current());
  EXPECT_TRUE(lidar_first.current()->T_camera_lidar.isApprox(camera_first.current()->T_camera_lidar, 1e-12));
  EXPECT_EQ(lidar_first.version(), camera_first.version());
}

TEST(Calibrator, RepeatedMotionsStartNoRound) {
  const Rig rig(6);
  Calibrator calibrator(Settings());
  PlayPairs(calibrator, rig, 6);
  const int version = calibrator.version();
  for (int k = 0; k < 6; ++k) {
    EXPECT_TRUE(calibrator.OnMotion(rig.Lidar(k), 0).empty());
    EXPECT_TRUE(calibrator.OnMotion(rig.FrontEndCamera(k), 0).empty());
  }
  EXPECT_EQ(calibrator.version(), version);
  EXPECT_EQ(calibrator.pairs(), 6);
}

TEST(Calibrator, AnswersToAnyButTheAwaitedVersionAreIgnored) {
  const Rig rig(8);
  Calibrator calibrator(Settings());
  PlayPairs(calibrator, rig, 7);
  calibrator.OnMotion(rig.Lidar(7), 0);
  const auto first = calibrator.OnMotion(rig.FrontEndCamera(7), 0);
  ASSERT_TRUE(!first.empty() && first.back().asks());
  const CalibrationVersion request = first.back();
  const auto next = calibrator.OnFusedMotions(request.version, rig.Fused(request), 0);
  ASSERT_FALSE(next.empty());
  // The same answer again (a repeat), an old version (out of order) and a version not yet sent: nothing.
  EXPECT_TRUE(calibrator.OnFusedMotions(request.version, rig.Fused(request), 0).empty());
  EXPECT_TRUE(calibrator.OnFusedMotions(request.version - 3, rig.Fused(request), 0).empty());
  EXPECT_TRUE(calibrator.OnFusedMotions(calibrator.version() + 5, rig.Fused(request), 0).empty());
  // The version now awaited is answered.
  ASSERT_TRUE(next.back().asks()) << "the round converged at its first scaled iteration";
  EXPECT_FALSE(calibrator.OnFusedMotions(next.back().version, rig.Fused(next.back()), 0).empty());
}

TEST(Calibrator, AnUnansweredRequestIsRepeatedAfterRetryUnderTheSameVersion) {
  const Rig rig(8);
  Calibrator calibrator(Settings());
  std::vector<CalibrationVersion> last;
  for (int k = 0; k < 8; ++k) {
    calibrator.OnMotion(rig.Lidar(k), 0);
    last = calibrator.OnMotion(rig.FrontEndCamera(k), 10 * kSecond);
  }
  // Fusion odometry never answered (it was restarting): the request is repeated after retry_s, not before.
  ASSERT_TRUE(!last.empty() && last.back().asks());
  EXPECT_FALSE(calibrator.Tick(12 * kSecond));
  const auto repeat = calibrator.Tick(13 * kSecond + 1);
  ASSERT_TRUE(repeat);
  EXPECT_EQ(repeat->version, last.back().version);
  EXPECT_EQ(repeat->used, last.back().used);
  EXPECT_EQ(calibrator.retries(), 1);
  EXPECT_FALSE(calibrator.Tick(14 * kSecond)) << "the next repeat waits retry_s again";
  // The restarted stage answers: the round goes on to convergence and nothing is repeated any more.
  AnswerAll(calibrator, rig, calibrator.OnFusedMotions(repeat->version, rig.Fused(*repeat), 20 * kSecond),
            20 * kSecond);
  EXPECT_TRUE(calibrator.converged());
  EXPECT_FALSE(calibrator.Tick(100 * kSecond));
}

TEST(Calibrator, ARestartedLoopReachesTheSameEstimateFromRepeatedMotions) {
  const Rig rig(10);
  Calibrator first(Settings());
  PlayPairs(first, rig, 10);
  // The restarted hand-eye process hears every motion again, all at once.
  Calibrator restarted(Settings());
  std::vector<CalibrationVersion> versions;
  for (int k = 0; k < 10; ++k) restarted.OnMotion(rig.Lidar(k), 0);
  for (int k = 0; k < 10; ++k) {
    const auto v = restarted.OnMotion(rig.FrontEndCamera(k), 0);
    if (k < 9) continue;  // answer only the newest round, as a busy fusion odometry would
    AnswerAll(restarted, rig, v, 0);
  }
  ASSERT_TRUE(first.converged() && restarted.converged());
  EXPECT_LT(RotationErrorDeg(first.current()->T_camera_lidar.linear(), restarted.current()->T_camera_lidar.linear()),
            0.01);
  EXPECT_LT((first.current()->T_camera_lidar.translation() - restarted.current()->T_camera_lidar.translation()).norm(),
            1e-3);
}

TEST(Calibrator, FailedMotionsNeverPairAndFailedAnswersKeepTheEstimate) {
  const Rig rig(8);
  Calibrator calibrator(Settings());
  PlayPairs(calibrator, rig, 8);
  ASSERT_TRUE(calibrator.converged());
  const Isometry3 before = calibrator.current()->T_camera_lidar;
  // A motion the LiDAR stage could not compute completes no pair.
  SensorMotion failed = rig.Lidar(0);
  failed.station_i = 50;
  failed.station_j = 51;
  failed.valid = false;
  failed.failure_reason = "too few points";
  EXPECT_TRUE(calibrator.OnMotion(failed, 0).empty());
  SensorMotion camera = rig.FrontEndCamera(1);
  camera.station_i = 50;
  camera.station_j = 51;
  EXPECT_TRUE(calibrator.OnMotion(camera, 0).empty());
  EXPECT_EQ(calibrator.pairs(), 8);
  // A new pair whose metric motions all fail: a FAILED version that keeps the estimate and says why.
  Rig more(9);
  calibrator.OnMotion(more.Lidar(8), 0);
  const auto v = calibrator.OnMotion(more.FrontEndCamera(8), 0);
  ASSERT_TRUE(!v.empty() && v.back().asks());
  std::vector<SensorMotion> answers = rig.Fused(v.back());
  for (auto& m : answers) {
    m.valid = false;
    m.failure_reason = "no tracks";
  }
  const auto out = calibrator.OnFusedMotions(v.back().version, answers, 0);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].status, VersionStatus::kFailed);
  EXPECT_NE(out[0].result.message.find("fusion odometry failed for"), std::string::npos) << out[0].result.message;
  EXPECT_NE(out[0].result.message.find("no tracks"), std::string::npos);
  EXPECT_TRUE(out[0].result.T_camera_lidar.isApprox(calibrator.current()->T_camera_lidar));
  EXPECT_LT(RotationErrorDeg(before.linear(), out[0].result.T_camera_lidar.linear()), 1.0);
  EXPECT_EQ(calibrator.awaiting_version(), -1);
}

TEST(Calibrator, BeyondMaxMotionsPairsAreDroppedForGoodAndListedOnce) {
  const Rig rig(14);
  CalibratorSettings settings = Settings();
  settings.max_motions = 8;
  Calibrator calibrator(settings);
  std::set<StationPair> listed_dropped;
  for (int k = 0; k < 14; ++k) {
    calibrator.OnMotion(rig.Lidar(k), 0);
    const auto seen = AnswerAll(calibrator, rig, calibrator.OnMotion(rig.FrontEndCamera(k), 0), 0);
    ASSERT_FALSE(seen.empty());
    std::set<StationPair> listed(seen.front().used.begin(), seen.front().used.end());
    listed.insert(seen.front().not_used.begin(), seen.front().not_used.end());
    EXPECT_EQ(listed.count({k, k + 1}), 1u) << "the new pair is answered, even when it is dropped at once";
    EXPECT_LE(calibrator.pairs(), 8);
  }
  EXPECT_EQ(calibrator.pairs(), 8);
  EXPECT_EQ(calibrator.dropped_pairs(), 6);
  // A dropped pair's motions, sent again, do not bring it back.
  for (int k = 0; k < 14; ++k) {
    calibrator.OnMotion(rig.Lidar(k), 0);
    calibrator.OnMotion(rig.FrontEndCamera(k), 0);
  }
  EXPECT_EQ(calibrator.pairs(), 8);
}

TEST(Calibrator, TooFewPairsWaitWithoutAskingAndScaledRefinementCanBeOff) {
  const Rig rig(8);
  Calibrator calibrator(Settings());
  calibrator.OnMotion(rig.Lidar(0), 0);
  const auto one = calibrator.OnMotion(rig.FrontEndCamera(0), 0);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_FALSE(one[0].asks());
  EXPECT_NE(calibrator.state().find("waiting for motions"), std::string::npos) << calibrator.state();

  CalibratorSettings scaleless = Settings();
  scaleless.scaled_refinement = false;
  Calibrator only_scaleless(scaleless);
  std::vector<CalibrationVersion> last;
  for (int k = 0; k < 8; ++k) {
    only_scaleless.OnMotion(rig.Lidar(k), 0);
    last = only_scaleless.OnMotion(rig.FrontEndCamera(k), 0);
    ASSERT_EQ(last.size(), 1u);
    EXPECT_FALSE(last[0].asks());
  }
  EXPECT_FALSE(only_scaleless.current()->scaled);
  EXPECT_EQ(only_scaleless.awaiting_version(), -1);
}

TEST(CalibratorSettings, ValidateNamesTheField) {
  CalibratorSettings s;
  EXPECT_EQ(s.Validate(), "");
  s.retry_s = -1;
  EXPECT_NE(s.Validate().find("retry_s"), std::string::npos);
  s = CalibratorSettings();
  s.max_motions = 1;
  EXPECT_NE(s.Validate().find("max_motions"), std::string::npos);
}

}  // namespace
}  // namespace fusecal
