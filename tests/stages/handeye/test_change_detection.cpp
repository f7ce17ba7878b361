// A sensor moved on its mount mid-session: the loop tells a change from an outlier, locates it between two
// stations, and converges again from the motions after it.
#include <gtest/gtest.h>

#include <optional>
#include <random>

#include "stages/foundation/se3.hpp"
#include "stages/handeye/calibrator.hpp"
#include "stages/handeye/calibrator_playback.hpp"
#include "stages/handeye/change_detection.hpp"
#include "stages/handeye/handeye_solver.hpp"
#include "stages/handeye/synthetic_motions.hpp"
#include "tests/support/turn_pair.hpp"

namespace fusecal {
namespace {

// A session of motion pairs k: station k -> k + 1, whose extrinsic X changes to X' in pair change_at.
struct Session {
  Isometry3 X, X_after;
  std::vector<MotionPair> metric;  // camera motions metric

  Session(int pairs, int change_at_pair, const Isometry3& delta, uint32_t seed, double rot_noise_deg = 0.02,
          double trans_noise_m = 0.0005) {
    SyntheticMotionSettings s;
    s.num_motions = pairs;
    s.min_angle_deg = 10;
    s.max_angle_deg = 30;
    s.rotation_noise_deg = rot_noise_deg;
    s.translation_noise_m = trans_noise_m;
    s.seed = seed;
    const ChangingMotionSet set = GenerateChangingMotions(s, change_at_pair, delta);
    X = set.before;
    X_after = set.after;
    metric = set.pairs;
  }
};

// Plays the session through the loop, answering every request with the metric camera motions.
void Play(Calibrator& calibrator, const Session& session, int from = 0, int to = -1) {
  PlayMetricPairs(calibrator, session.metric, from, to);
}

Isometry3 Delta(double roll_deg, double x_m) {
  Isometry3 d = Isometry3::Identity();
  d.linear() = Eigen::AngleAxisd(roll_deg * M_PI / 180, Eigen::Vector3d::UnitX()).toRotationMatrix();
  d.translation() = Eigen::Vector3d(x_m, 0, 0);
  return d;
}

TEST(ChangeThresholds, MatchTables) {
  EXPECT_NEAR(ChiSquareQuantile(6, 1e-3), 22.458, 0.01);
  EXPECT_NEAR(ChiSquareQuantile(3, 1e-3), 16.266, 0.01);
  EXPECT_NEAR(ChiSquareQuantile(3, 0.05), 7.815, 0.01);
  EXPECT_NEAR(ChiSquareQuantile(2, 0.01), 9.210, 0.01);
  // With the noise estimated from few residuals, dof times the F quantile: F(3, 10) at 0.05 is 3.708,
  // F(6, 20) at 0.001 is 6.0186 (by numerical integration of its density); with many it is chi^2.
  EXPECT_NEAR(TestThreshold(3, 10, 0.05), 3 * 3.708, 0.01);
  EXPECT_NEAR(TestThreshold(6, 20, 0.001), 6 * 6.0186, 0.01);
  EXPECT_NEAR(TestThreshold(6, 5000, 0.001), ChiSquareQuantile(6, 0.001), 1e-9);
}

// Tests whose residuals respond to delta as the identity: a pair "sees" delta fully.
PairTest MakeTest(int i, double d2, bool off, const Vector6& residual) {
  PairTest t;
  t.station_i = i;
  t.station_j = i + 1;
  t.d2 = d2;
  t.dof = 6;
  t.noise_dof = 10000;  // a known noise
  t.off = off;
  t.whitened_jacobian = Eigen::MatrixXd::Identity(6, 6);
  t.whitened_change_jacobian = -Eigen::MatrixXd::Identity(6, 6);
  t.whitened_residual = residual;
  return t;
}

TEST(ChangeDetector, AnOffPairIsAChangeOnlyWhenThePairsAfterItConfirmIt) {
  ChangeDetector detector;
  const Vector6 quiet = Vector6::Constant(0.5), moved = Vector6::Constant(3.0);
  EXPECT_FALSE(detector.Add(MakeTest(0, 1.5, false, quiet)));
  EXPECT_FALSE(detector.Add(MakeTest(1, 100, true, moved)));  // an outlier ...
  EXPECT_FALSE(detector.Add(MakeTest(2, 1.5, false, quiet)));
  EXPECT_FALSE(detector.Add(MakeTest(3, 1.5, false, quiet)));
  EXPECT_FALSE(detector.Add(MakeTest(4, 1.5, false, quiet)));       // ... that the pairs after it do not confirm
  EXPECT_FALSE(detector.Add(MakeTest(5, 100, true, moved)));        // the pair across a change ...
  const auto change = detector.Add(MakeTest(6, 54, false, moved));  // ... and one after it, not off alone
  ASSERT_TRUE(change);
  EXPECT_EQ(*change, 5) << "the change lies in the off pair";
  EXPECT_TRUE(detector.recent().empty());
  // The pair's metric test replaces its scaleless one, and a scaleless test after it is ignored.
  EXPECT_FALSE(detector.Add(MakeTest(6, 100, true, moved)));
  EXPECT_TRUE(detector.Suspicious());
  PairTest metric = MakeTest(6, 1, false, quiet);
  metric.metric = true;
  EXPECT_FALSE(detector.Add(metric));
  ASSERT_EQ(detector.recent().size(), 1u);
  EXPECT_FALSE(detector.recent()[0].test.off);
  EXPECT_FALSE(detector.Add(MakeTest(6, 100, true, moved)));
  ASSERT_EQ(detector.recent().size(), 1u);
  EXPECT_TRUE(detector.recent()[0].test.metric);
  EXPECT_FALSE(detector.Suspicious());
}

TEST(ChangeDetector, ScalelessMotionsOffByTheFrontEndAloneDoNotConfirmEachOther) {
  // Two pairs whose 5-point rotations miss the same way while fusion odometry's metric motions of the same
  // pairs fit: without the metric tests, the second confirms the first.
  const Vector6 quiet = Vector6::Constant(0.5), missed = Vector6::Constant(3.0);
  const auto play = [&](bool with_metric) {
    ChangeDetector detector;
    std::optional<int> change;
    for (int k = 0; k < 3; ++k) {
      const bool outlier = k == 0 || k == 2;
      change = change ? change : detector.Add(MakeTest(k, outlier ? 54 : 1.5, outlier, outlier ? missed : quiet));
      PairTest metric = MakeTest(k, 1.5, false, quiet);
      metric.metric = true;
      if (with_metric && k < 2) change = change ? change : detector.Add(metric);
    }
    return change;
  };
  EXPECT_TRUE(play(false)) << "the scaleless tests alone read as a change";
  EXPECT_FALSE(play(true));
}

TEST(ChangeDetector, PairsAfterTheChangeConfirmTheChangeThatTheOffPairShows) {
  // A translation across turns: the pair across the change shows all of it, a pair after it 0.25 of it,
  // too little for the test of a common change in any direction, enough along the one the off pair shows.
  const auto play = [](double after_sign) {
    ChangeDetector detector;
    Vector6 delta = Vector6::Zero();
    delta(3) = 8;
    EXPECT_FALSE(detector.Add(MakeTest(0, 64, true, -delta)));  // r_s = K delta, K = -I
    std::optional<int> change;
    for (int k = 1; k <= 2; ++k) {
      PairTest after = MakeTest(k, 4.0, false, -0.25 * after_sign * delta);  // r_i = -J_X delta
      after.whitened_jacobian *= 0.25;
      change = detector.Add(after);
      if (k == 1) {
        EXPECT_FALSE(change) << "one pair after it is not enough";
      }
    }
    return change;
  };
  const auto change = play(1.0);
  ASSERT_TRUE(change);
  EXPECT_EQ(*change, 0);
  EXPECT_FALSE(play(-1.0)) << "pairs that move the other way do not confirm it";
}

TEST(TestPair, TheNoiseOfAnEstimateFromFewPairsHasItsDegreesOfFreedom) {
  const Session session(4, -1, Isometry3::Identity(), 3);
  HandEyeResult estimate;
  estimate.T_camera_lidar = session.X;
  estimate.used_pairs.resize(3);
  estimate.noise_rot_deg = 0.012;  // above the floor (0.05 of the nominal 0.1 deg)
  estimate.noise_trans_m = 0.0002;
  const ChangeDetectionSettings settings;
  // Rotation from its 9 residuals less 3 unknowns: F(6, 6), not F(6, 3), whose quantile at 5e-4 is 8 times larger.
  EXPECT_EQ(TestPair(session.metric[3], estimate, HandEyeSettings{}, settings).noise_dof, 6);
  EXPECT_GT(TestThreshold(6, 3, 5e-4), 8 * TestThreshold(6, 6, 5e-4));
  estimate.noise_rot_deg = 0.004;  // both below the floor: a known noise
  EXPECT_EQ(TestPair(session.metric[3], estimate, HandEyeSettings{}, settings).noise_dof, kKnownNoiseDof);
}

TEST(TestPair, ATranslationAloneIsTestedAgainstTheTranslationNoiseAlone) {
  HandEyeResult estimate;
  estimate.used_pairs.resize(3);
  estimate.noise_rot_deg = 0.012;  // both estimated from 3 pairs: F with 6 degrees of freedom
  estimate.noise_trans_m = 0.0006;
  const ChangeDetectionSettings settings;
  const Session unchanged(4, -1, Isometry3::Identity(), 3);
  estimate.T_camera_lidar = unchanged.X;
  EXPECT_FALSE(TestPair(unchanged.metric[3], estimate, HandEyeSettings{}, settings).off);
  // The camera shifts during pair 3: the smallest shift that makes it off is one the six rows together, at
  // F(6, 6), would not have called off.
  std::optional<PairTest> first_off;
  for (double x_m = 0.0005; x_m < 0.05 && !first_off; x_m += 0.0005) {
    const Session moved(4, 3, Delta(0, x_m), 3);
    const PairTest test = TestPair(moved.metric[3], estimate, HandEyeSettings{}, settings);
    if (test.off) first_off = test;
  }
  ASSERT_TRUE(first_off);
  EXPECT_LT(first_off->d2, TestThreshold(6, 6, settings.off_probability));
}

TEST(TestPair, FewPairsAtHandheldNoiseDoNotMakeTheNextPairsOff) {
  // Handheld noise (0.5 deg / 5 mm per axis and sensor motion): an estimate of 5 pairs, whose translation
  // residuals the rotation noise through the lever arm can explain alone, tests the next 35 of an unchanged rig.
  int off = 0, tested = 0, collapsed = 0;
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    const Session session(40, -1, Isometry3::Identity(), seed, 0.5, 0.005);
    const std::vector<MotionPair> first(session.metric.begin(), session.metric.begin() + 5);
    const HandEyeResult estimate = SolveScaled(first);
    ASSERT_TRUE(estimate.usable()) << estimate.message;
    collapsed += estimate.noise_trans_m < 0.001;
    for (size_t k = 5; k < session.metric.size(); ++k, ++tested)
      off += TestPair(session.metric[k], estimate, HandEyeSettings{}, ChangeDetectionSettings{}).off;
  }
  EXPECT_GT(collapsed, 0) << "no estimate whose translation noise fell below 1 mm: the case is not exercised";
  // alpha = 5e-4 per pair by design; allow a few for the estimates' own tails.
  EXPECT_LE(off, 3) << off << " of " << tested << " pairs off";
}

TEST(Calibrator, DetectsAMovedCameraWithinThreePairsAndConvergesToTheNewExtrinsic) {
  struct Case {
    double roll_deg, x_m;
  };
  for (const Case c : {Case{2.0, 0.03}, Case{0.5, 0.0}, Case{0.0, 0.02}}) {
    const Session session(40, 20, Delta(c.roll_deg, c.x_m), 5);
    Calibrator calibrator{CalibratorSettings{}};
    Play(calibrator, session);
    ASSERT_EQ(calibrator.changes().size(), 1u) << c.roll_deg << " deg, " << c.x_m << " m";
    const ExtrinsicChange& change = calibrator.changes()[0];
    EXPECT_EQ(change.after_station, 20);
    EXPECT_LE(change.decided_at_station, 21 + 3);
    EXPECT_LT(RotationErrorDeg(change.T_before.linear(), session.X.linear()), 0.1);
    ASSERT_TRUE(calibrator.converged()) << calibrator.state();
    const Isometry3 T = calibrator.current()->T_camera_lidar;
    EXPECT_LT(RotationErrorDeg(T.linear(), session.X_after.linear()), 0.1);
    EXPECT_LT((T.translation() - session.X_after.translation()).norm(), 0.003);
    // The pairs before the change (and the one across it) left the solve.
    for (const auto& p : calibrator.current()->used_pairs) EXPECT_GT(p.station_i, 20);
  }
}

// Fusion odometry's answer for an estimate that is not observable misses by about 0.2 deg: it projects the
// LiDAR's points with an extrinsic that is off along the unobservable direction.
FusedAnswer OffWhileDegenerate(std::mt19937& rng) {
  return [&rng](const CalibrationVersion& request, const MotionPair& pair) {
    std::normal_distribution<double> noise(0.0, 0.2 * M_PI / 180 / std::sqrt(3.0));
    Isometry3 A = pair.A;
    if (request.result.observability != Observability::kOk)
      A.linear() = A.linear() * ExpSO3(Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
    return A;
  };
}

// The first three motions all turn about the vertical, so the extrinsic is not observable before a change
// after station 3; the motions after it also tilt.
const Isometry3 kMountedCamera = [] {
  Isometry3 X = Isometry3::Identity();
  X.linear() =
      (Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.03, 0.12, -0.05);
  return X;
}();

std::vector<MotionPair> TurnsAboutTheVerticalFirst(const Isometry3& X, const Isometry3& X_after, std::mt19937& rng) {
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ(), y = Eigen::Vector3d::UnitY(), x = Eigen::Vector3d::UnitX();
  return {
      Turn(0, z, 15, {0.2, 0.05, 0}, X, X, rng),
      Turn(1, z, -22, {0.1, -0.1, 0}, X, X, rng),
      Turn(2, z, 18, {-0.15, 0.05, 0}, X, X, rng),
      Turn(3, y, 12, {0.05, 0, 0.1}, X, X_after, rng),  // across the change
      Turn(4, y, -14, {0.0, 0.05, -0.1}, X_after, X_after, rng),
      Turn(5, x, 10, {0.1, 0, 0.05}, X_after, X_after, rng),
      Turn(6, z, -20, {0.1, 0.1, 0}, X_after, X_after, rng),
      Turn(7, y, 15, {-0.1, 0, 0.1}, X_after, X_after, rng),
  };
}

TEST(Calibrator, AChangeAfterMotionsAboutOneAxisIsFoundFromTheScalelessEstimate) {
  // 1 deg about a tilted axis.
  std::mt19937 rng(3);
  const Isometry3 X = kMountedCamera;
  Isometry3 delta = Isometry3::Identity();
  delta.linear() = Eigen::AngleAxisd(1.0 * M_PI / 180, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix();
  Calibrator unchanged{CalibratorSettings{}};
  PlayMetricPairs(unchanged, TurnsAboutTheVerticalFirst(X, X, rng), 0, -1, OffWhileDegenerate(rng));
  EXPECT_TRUE(unchanged.changes().empty()) << "after station " << unchanged.changes()[0].after_station;

  const Isometry3 X_after = X * delta;
  Calibrator calibrator{CalibratorSettings{}};
  PlayMetricPairs(calibrator, TurnsAboutTheVerticalFirst(X, X_after, rng), 0, -1, OffWhileDegenerate(rng));
  ASSERT_EQ(calibrator.changes().size(), 1u) << calibrator.state();
  EXPECT_EQ(calibrator.changes()[0].after_station, 3);
  EXPECT_LE(calibrator.changes()[0].decided_at_station, 6) << "within 3 pairs of the change";
  ASSERT_TRUE(calibrator.current());
  EXPECT_LT(RotationErrorDeg(calibrator.current()->T_camera_lidar.linear(), X_after.linear()), 0.1);
}

TEST(Calibrator, ATranslationAloneAfterMotionsAboutOneAxisIsFoundByTheSplitTest) {
  // 3 cm, mostly along the vertical (the LiDAR's z) that the first turns leave unobserved. The scaleless
  // estimate those pairs are tested against sees no translation; once the estimate is observable, the
  // change-point test over the pairs finds it.
  Isometry3 delta = Isometry3::Identity();
  delta.translation() = 0.03 * Eigen::Vector3d(-0.12, 0.41, -0.9).normalized();
  const Isometry3 X = kMountedCamera, X_after = X * delta;
  for (const bool split_test : {true, false}) {
    std::mt19937 rng(5);
    CalibratorSettings settings;
    if (!split_test) settings.change_detection.split_min_noise_dof = 1000;  // never enough residuals
    Calibrator calibrator(settings);
    PlayMetricPairs(calibrator, TurnsAboutTheVerticalFirst(X, X_after, rng), 0, -1, OffWhileDegenerate(rng));
    if (!split_test) {
      EXPECT_TRUE(calibrator.changes().empty()) << "the pair-by-pair test alone found it: this tests nothing";
      continue;
    }
    ASSERT_EQ(calibrator.changes().size(), 1u) << calibrator.state();
    const ExtrinsicChange& change = calibrator.changes()[0];
    EXPECT_EQ(change.after_station, 3);
    EXPECT_LE(change.decided_at_station, 6) << "within 3 pairs of the change";
    // The extrinsic before: the solve of the pairs before the change, within 3 std of where it was (about the
    // vertical and along it, as uncertain as those pairs leave it).
    const Vector6 error = ExtrinsicError(change.T_before, X);
    for (int axis = 0; axis < 6; ++axis)
      EXPECT_LE(std::abs(error(axis)), 3 * std::sqrt(change.covariance_before(axis, axis))) << "axis " << axis;
    ASSERT_TRUE(calibrator.current());
    EXPECT_LT((calibrator.current()->T_camera_lidar.translation() - X_after.translation()).norm(), 0.003);
  }
  std::mt19937 rng(5);
  Calibrator unchanged{CalibratorSettings{}};
  PlayMetricPairs(unchanged, TurnsAboutTheVerticalFirst(X, X, rng), 0, -1, OffWhileDegenerate(rng));
  EXPECT_TRUE(unchanged.changes().empty()) << "after station " << unchanged.changes()[0].after_station;
}

TEST(Calibrator, NoChangeIsReportedOverALongSessionOfAnUnchangedRig) {
  for (uint32_t seed : {1u, 2u}) {
    const Session session(150, -1, Isometry3::Identity(), seed, 0.05, 0.001);
    Calibrator calibrator{CalibratorSettings{}};
    Play(calibrator, session);
    EXPECT_TRUE(calibrator.changes().empty())
        << "seed " << seed << ": after station " << calibrator.changes()[0].after_station;
    EXPECT_TRUE(calibrator.converged());
  }
}

TEST(Calibrator, ASingleBadPairIsAnOutlierNotAChange) {
  Session session(30, -1, Isometry3::Identity(), 7);
  // One camera motion far off (a bad match), in the middle of the session.
  session.metric[15].A = session.metric[15].A * Delta(5.0, 0.1);
  Calibrator calibrator{CalibratorSettings{}};
  Play(calibrator, session);
  EXPECT_TRUE(calibrator.changes().empty());
  EXPECT_TRUE(calibrator.converged());
  EXPECT_LT(RotationErrorDeg(calibrator.current()->T_camera_lidar.linear(), session.X.linear()), 0.1);
}

TEST(Calibrator, DetectionCanBeTurnedOffAndLateMotionsFromBeforeAChangeAreIgnored) {
  const Session session(30, 15, Delta(2.0, 0.03), 9);
  CalibratorSettings off;
  off.change_detection.enabled = false;
  Calibrator blind(off);
  Play(blind, session);
  EXPECT_TRUE(blind.changes().empty());

  Calibrator calibrator{CalibratorSettings{}};
  Play(calibrator, session);
  ASSERT_EQ(calibrator.changes().size(), 1u);
  const int pairs = calibrator.pairs();
  // A motion from before the change, repeated by a restarted stage, stays out.
  Play(calibrator, session, 3, 4);
  EXPECT_EQ(calibrator.pairs(), pairs);
  EXPECT_EQ(calibrator.changes().size(), 1u);
}

}  // namespace
}  // namespace fusecal
