// The verdict from the noise the data show, its hysteresis, outlier rejection that cannot cascade, and
// camera trajectories with one global scale.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "stages/foundation/observed_covariance.hpp"
#include "stages/foundation/se3.hpp"
#include "stages/handeye/global_scale.hpp"
#include "stages/handeye/handeye_solver.hpp"
#include "stages/handeye/outlier_rejection.hpp"
#include "stages/handeye/synthetic_motions.hpp"

namespace fusecal {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Scaled motions mostly about the LiDAR's z axis, two tilts about x, short translations (0.1 m, so that
// their lever arm says little): the rotation about z is known through the tilts, to about sigma / tilt.
// Both sensors get `noise_deg` per axis and 3 mm.
std::vector<MotionPair> MostlyOneAxis(double tilt_deg, double noise_deg, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Isometry3 X = MakeIsometry(ExpSO3(Eigen::Vector3d(0.3, -1.2, 0.4)), Eigen::Vector3d(0.05, -0.1, 0.2));
  std::vector<MotionPair> pairs;
  for (int k = 0; k < 14; ++k) {
    const bool tilt = k == 4 || k == 9;
    const double angle = tilt ? tilt_deg : 20.0 + 10.0 * u(rng);
    const Eigen::Vector3d axis = tilt ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ();
    const Isometry3 B =
        MakeIsometry(ExpSO3(axis * angle * kDeg * (k % 2 ? 1 : -1)), 0.1 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
    const Isometry3 A = X * B * X.inverse();
    const auto noisy = [&](const Isometry3& T) {
      const Eigen::Vector3d d(n(rng), n(rng), n(rng));
      const Eigen::Vector3d e(n(rng), n(rng), n(rng));
      return MakeIsometry(T.linear() * ExpSO3(d * noise_deg * kDeg), T.translation() + 0.003 * e);
    };
    MotionPair p;
    p.station_i = k;
    p.station_j = k + 1;
    p.A = noisy(A);
    p.B = noisy(B);
    pairs.push_back(p);
  }
  return pairs;
}

// The same motions: judged at the nominal 0.1 deg they look observable; their residuals show 0.4 deg, and
// at that noise the rotation about z is not determined.
TEST(HandEyeVerdict, NoiseTheResidualsShowDecidesTheVerdict) {
  const auto pairs = MostlyOneAxis(12.0, 0.4, 3);
  HandEyeSettings nominal_only;
  nominal_only.estimate_noise_from_residuals = false;
  const HandEyeResult at_nominal = SolveScaled(pairs, nominal_only);
  const HandEyeResult shown = SolveScaled(pairs);
  ASSERT_TRUE(at_nominal.usable() && shown.usable()) << shown.message;
  EXPECT_EQ(at_nominal.observability, Observability::kOk) << at_nominal.message;
  EXPECT_EQ(shown.observability, Observability::kRotationDegenerate) << shown.message;
  EXPECT_GT(shown.noise_rot_deg, 0.25);
  EXPECT_GT(shown.verdict_rotation_std_deg, 2.5 * at_nominal.verdict_rotation_std_deg);
  // The unobservable direction named is the rotation axis, z of the LiDAR in the camera frame.
  const Eigen::Vector3d z_camera = ExpSO3(Eigen::Vector3d(0.3, -1.2, 0.4)) * Eigen::Vector3d::UnitZ();
  EXPECT_GT(std::abs(shown.unobservable_direction.dot(z_camera)), 0.95);
  EXPECT_NE(shown.message.find("observed part"), std::string::npos) << shown.message;
}

// Near a threshold a verdict stays what it was: leaving it needs a crossing by 20 %.
TEST(HandEyeVerdict, HysteresisKeepsAVerdictNearItsThreshold) {
  const auto pairs = MostlyOneAxis(12.0, 0.1, 5);
  const HandEyeResult plain = SolveScaled(pairs);
  ASSERT_TRUE(plain.usable()) << plain.message;
  const double std_deg = plain.verdict_rotation_std_deg;
  ASSERT_GT(std_deg, 0.0);
  const auto verdict = [&](double threshold, std::optional<Observability> previous) {
    HandEyeSettings s;
    s.max_rotation_std_deg = threshold;
    s.max_translation_std_m = 10.0;
    s.previous_verdict = previous;
    return SolveScaled(pairs, s).observability;
  };
  const auto ok = Observability::kOk, degenerate = Observability::kRotationDegenerate;
  // The std at 0.9 x the threshold: observed, unless it was degenerate before (0.9 > 0.8).
  EXPECT_EQ(verdict(std_deg / 0.9, std::nullopt), ok);
  EXPECT_EQ(verdict(std_deg / 0.9, degenerate), degenerate);
  EXPECT_EQ(verdict(std_deg / 0.9, ok), ok);
  // At 1.1 x the threshold: degenerate, unless it was observed before (1.1 < 1.2).
  EXPECT_EQ(verdict(std_deg / 1.1, std::nullopt), degenerate);
  EXPECT_EQ(verdict(std_deg / 1.1, ok), ok);
  EXPECT_EQ(verdict(std_deg / 1.1, degenerate), degenerate);
  // Clearly beyond: the verdict changes whatever it was.
  EXPECT_EQ(verdict(std_deg / 1.5, ok), degenerate);
  EXPECT_EQ(verdict(std_deg / 0.5, degenerate), ok);
}

// A drive turning about the vertical, with a little pitch and roll, seen by two chained odometries (each
// step adds its own noise, so a motion over five steps carries five steps' noise).
struct ChainedDrive {
  Isometry3 X;
  std::vector<Isometry3> camera, lidar;  // odometry poses, frame 0 at the identity
};

ChainedDrive MakeChainedDrive(std::uint32_t seed, double wobble_deg = 0.3) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  const auto noise = [&](double rot_deg, double trans_m) {
    return MakeIsometry(ExpSO3(rot_deg * kDeg * Eigen::Vector3d(n(rng), n(rng), n(rng))),
                        trans_m * Eigen::Vector3d(n(rng), n(rng), n(rng)));
  };
  ChainedDrive d;
  d.X = MakeIsometry(RotationFromRpy(-90 * kDeg, 0, -90 * kDeg), Eigen::Vector3d(0.05, -0.1, -0.3));
  d.camera.assign(1, Isometry3::Identity());
  d.lidar.assign(1, Isometry3::Identity());
  for (int k = 1; k < 80; ++k) {
    const Eigen::Vector3d turn(wobble_deg * kDeg * n(rng), wobble_deg * kDeg * n(rng), 8.0 * kDeg * std::sin(0.25 * k));
    const Isometry3 step = MakeIsometry(ExpSO3(turn), Eigen::Vector3d(1.0, 0.0, 0.0));
    d.lidar.push_back(d.lidar.back() * step * noise(0.15, 0.01));
    d.camera.push_back(d.camera.back() * d.X * step * d.X.inverse() * noise(0.15, 0.01));
  }
  return d;
}

std::vector<MotionPair> Windows(const ChainedDrive& d, int length, int stride) {
  std::vector<MotionPair> pairs;
  for (int k = 0; k + length < static_cast<int>(d.lidar.size()); k += stride) {
    MotionPair p;
    p.station_i = k;
    p.station_j = k + length;
    p.A = d.camera[k].inverse() * d.camera[k + length];
    p.B = d.lidar[k].inverse() * d.lidar[k + length];
    pairs.push_back(p);
  }
  return pairs;
}

// The same drive cut into disjoint five-step motions (15 pairs) or into one five-step motion starting at
// every step (75 pairs that overlap): the overlapping pairs carry no more information, and the solve must
// not claim they do. Their residuals, and the shares of the estimate they make, are correlated in sequence
// (about 1 - lag / 5), which counts them as about 15 independent pairs: the verdict's and the reported std stay those
// of the disjoint pairs (without the correction they were sqrt(5) smaller, and the verdict could call the rotation
// observed).
TEST(HandEyeVerdict, OverlappingWindowsCountAsFewerPairs) {
  for (std::uint32_t seed = 1; seed <= 4; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const ChainedDrive drive = MakeChainedDrive(seed);
    const HandEyeResult disjoint = SolveScaled(Windows(drive, 5, 5));
    const HandEyeResult overlapping = SolveScaled(Windows(drive, 5, 1));
    ASSERT_TRUE(disjoint.usable() && overlapping.usable()) << overlapping.message;
    EXPECT_GT(overlapping.serial_correlation_inflation, 3.0);
    EXPECT_LT(overlapping.serial_correlation_inflation, 7.0);
    EXPECT_NE(overlapping.message.find("correlated in sequence"), std::string::npos) << overlapping.message;
    const double ratio = overlapping.verdict_rotation_std_deg / disjoint.verdict_rotation_std_deg;
    EXPECT_GT(ratio, 0.7) << overlapping.message;
    EXPECT_LT(ratio, 1.4) << overlapping.message;
    // The weak translation (along the vertical) is seen through each window's wobble, which differs from
    // window to window: the shares decorrelate faster than the rotation's (kappa 2.6-3.0 against 3.1-4.5),
    // and over 100 drives the ratio of the verdicts' translation std is 0.77 on average.
    EXPECT_GT(overlapping.verdict_translation_std_m, 0.5 * disjoint.verdict_translation_std_m);
    for (int k = 0; k < 3; ++k) EXPECT_GT(overlapping.std_dev_rot_deg(k), 0.7 * disjoint.std_dev_rot_deg(k));
  }
}

// A drive on a flat road (0.02 deg of pitch and roll per step) turns about the vertical only. The height
// of the camera over the LiDAR (t along the vertical) is then not observed; the rotation about the
// vertical only through the directions of travel. Whether the motions are disjoint or overlapping windows,
// the result is never "converged", the direction it names is the vertical, and the observed part of the
// rotation is known to well within 1 deg.
TEST(HandEyeVerdict, AFlatDriveNeverConvergesAndNamesTheVertical) {
  for (std::uint32_t seed = 1; seed <= 4; ++seed) {
    const ChainedDrive drive = MakeChainedDrive(seed, 0.02);
    const Eigen::Vector3d vertical = drive.X.linear() * Eigen::Vector3d::UnitZ();  // camera frame
    for (int stride : {5, 1}) {
      SCOPED_TRACE("seed " + std::to_string(seed) + ", stride " + std::to_string(stride));
      const HandEyeResult r = SolveScaled(Windows(drive, 5, stride));
      ASSERT_TRUE(r.usable()) << r.message;
      EXPECT_NE(r.status, HandEyeStatus::kConverged) << r.message;
      EXPECT_NE(r.observability, Observability::kOk) << r.message;
      EXPECT_GT(std::abs(r.unobservable_direction.dot(vertical)), 0.95) << r.message;
      const ObservedUncertainty observed =
          ObservedPart(r.covariance, r.T_camera_lidar.linear(), r.unobservable_direction);
      EXPECT_LT(observed.max_rotation_std_deg, 1.0) << r.message;
      EXPECT_GT(observed.max_rotation_std_deg, 0.0);
    }
  }
}

// Independent pairs are not inflated: over 40 sets of random motions, almost all get kappa = 1 exactly.
TEST(HandEyeVerdict, IndependentPairsAreNotInflated) {
  int inflated = 0;
  double sum = 0.0;
  for (std::uint32_t seed = 1; seed <= 40; ++seed) {
    const auto data = GenerateSyntheticMotions([seed] {
      SyntheticMotionSettings s;
      s.num_motions = 10;
      s.rotation_noise_deg = 0.1;
      s.translation_noise_m = 0.005;
      s.seed = seed;
      return s;
    }());
    const HandEyeResult r = SolveScaled(data.pairs);
    ASSERT_TRUE(r.usable()) << r.message;
    inflated += r.serial_correlation_inflation > 1.0;
    sum += r.serial_correlation_inflation;
  }
  EXPECT_LE(inflated, 4);
  EXPECT_LT(sum / 40, 1.1);
}

// Errors within what the nominal noise gives are not outliers, however the others look: a third of the
// pairs with 2-4 cm translation errors among exact ones (the median of all is ~1 mm) stay in.
TEST(HandEyeOutlierRejection, ErrorsWithinTheNominalNoiseDoNotCascade) {
  auto data = GenerateSyntheticMotions([] {
    SyntheticMotionSettings s;
    s.num_motions = 15;
    s.seed = 41;
    s.rotation_noise_deg = 0.01;
    s.translation_noise_m = 0.0005;
    return s;
  }());
  for (int k = 0; k < 15; k += 3) data.pairs[k].A.translation() += Eigen::Vector3d(0.02 + 0.004 * k / 3, 0.0, 0.0);
  const HandEyeResult r = SolveScaled(data.pairs);
  ASSERT_TRUE(r.usable()) << r.message;
  EXPECT_TRUE(r.rejected_pairs.empty()) << r.rejected_pairs.front().reason;
  EXPECT_EQ(r.used_pairs.size(), 15u);
}

// The mechanism: limits from every pair (set aside ones included), and a pair set aside comes back when
// the estimate explains it.
TEST(HandEyeOutlierRejection, APairSetAsideComesBackWhenExplained) {
  std::vector<MotionPair> input(6);
  for (int k = 0; k < 6; ++k) input[k].station_i = k;
  handeye::PairSet set;
  for (int k = 0; k < 6; ++k) {
    set.index.push_back(k);
    set.pairs.push_back(input[k]);
  }
  std::vector<double> rot_deg = {0.1, 0.12, 0.09, 0.11, 5.0, 0.1};  // pair 4 is far off
  const auto residuals = [&](const MotionPair& p) { return std::make_pair(rot_deg[p.station_i], 0.001); };
  HandEyeSettings s;
  s.nominal_rotation_sigma_deg = 0.01;  // limits from the residuals: 4 x median 0.1 deg
  const handeye::NoiseModel nominal{0.01 * kDeg, 0.001, std::nullopt};
  ASSERT_TRUE(handeye::RejectOrRestoreOne(&set, input, residuals, nominal, s));
  ASSERT_EQ(set.outliers.count(4), 1u);
  EXPECT_EQ(set.size(), 5);
  EXPECT_FALSE(handeye::RejectOrRestoreOne(&set, input, residuals, nominal, s));  // nothing else is off
  rot_deg[4] = 0.1;                                                               // a better estimate explains it
  ASSERT_TRUE(handeye::RejectOrRestoreOne(&set, input, residuals, nominal, s));
  EXPECT_TRUE(set.outliers.empty());
  EXPECT_EQ(set.index, (std::vector<int>{0, 1, 2, 3, 4, 5}));
}

// The rotation-agreement limit grows with the turn: a 25 deg turn whose two angles differ by 2 deg (a
// timing error grows with the turn) is kept; at 3 deg of turn the same 2 deg are too much.
TEST(HandEyeScreening, AngleAgreementLimitGrowsWithTheTurn) {
  const auto pair_with = [](double angle_deg, double difference_deg) {
    MotionPair p;
    p.B = MakeIsometry(ExpSO3(Eigen::Vector3d::UnitZ() * angle_deg * kDeg), Eigen::Vector3d(1, 0, 0));
    p.A =
        MakeIsometry(ExpSO3(Eigen::Vector3d::UnitY() * (angle_deg + difference_deg) * kDeg), Eigen::Vector3d(0, 1, 0));
    return p;
  };
  HandEyeSettings s;
  s.min_pairs = 2;
  const HandEyeResult large = SolveScaled({pair_with(25, 2), pair_with(30, 0)}, s);
  const HandEyeResult small = SolveScaled({pair_with(3, 2), pair_with(30, 0)}, s);
  bool large_rejected_for_angles = false, small_rejected_for_angles = false;
  for (const auto& r : large.rejected_pairs)
    large_rejected_for_angles |= r.reason.find("angles disagree") != std::string::npos;
  for (const auto& r : small.rejected_pairs)
    small_rejected_for_angles |= r.reason.find("angles disagree") != std::string::npos;
  EXPECT_FALSE(large_rejected_for_angles);
  EXPECT_TRUE(small_rejected_for_angles);
}

}  // namespace
}  // namespace fusecal

namespace fusecal {
namespace {

// A camera trajectory known up to one scale (0.37 of metric): the extrinsic comes out as from metric
// motions, and lambda = 1 / 0.37 with a standard deviation that covers its error.
TEST(HandEyeGlobalScale, RecoversTheExtrinsicAndTheScaleOfATrajectory) {
  SyntheticMotionSettings settings;
  settings.num_motions = 12;
  settings.seed = 17;
  settings.rotation_noise_deg = 0.02;
  settings.translation_noise_m = 0.002;
  SyntheticMotionSet set = GenerateSyntheticMotions(settings);
  const HandEyeResult metric = SolveScaled(set.pairs);
  for (auto& p : set.pairs) {
    p.A.translation() *= 0.37;
    p.camera_scaled = false;
  }
  const HandEyeResult global = SolveGlobalScale(set.pairs);
  ASSERT_TRUE(global.usable()) << global.message;
  EXPECT_EQ(global.status, HandEyeStatus::kConverged) << global.message;
  EXPECT_TRUE(global.scaled);
  ASSERT_EQ(global.scales.size(), 1u);
  EXPECT_NEAR(global.scales[0], 1 / 0.37, 3 * global.scale_std_devs[0] + 1e-9);
  EXPECT_LT(global.scale_std_devs[0], 0.05);
  EXPECT_LT(RotationErrorDeg(global.T_camera_lidar.linear(), set.T_camera_lidar.linear()), 0.05);
  EXPECT_LT((global.T_camera_lidar.translation() - set.T_camera_lidar.translation()).norm(), 0.01);
  // As good as the metric motions (up to the noise the scale adds).
  EXPECT_LT((global.T_camera_lidar.translation() - metric.T_camera_lidar.translation()).norm(), 0.005);
  EXPECT_NE(global.message.find("global camera scale"), std::string::npos) << global.message;
}

// Camera translations that point against the LiDAR's everywhere: no positive scale, a failure that says so.
TEST(HandEyeGlobalScale, ANegativeScaleIsAFailureThatSaysSo) {
  SyntheticMotionSettings settings;
  settings.num_motions = 10;
  settings.seed = 18;
  SyntheticMotionSet set = GenerateSyntheticMotions(settings);
  for (auto& p : set.pairs) p.A.translation() *= -0.5;
  HandEyeSettings s;
  s.reject_outliers = false;
  const HandEyeResult r = SolveGlobalScale(set.pairs, s);
  EXPECT_FALSE(r.converged);
  EXPECT_NE(r.message.find("global camera scale is not determined"), std::string::npos) << r.message;
}

}  // namespace
}  // namespace fusecal
