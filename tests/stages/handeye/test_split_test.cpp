// The change-point test over the pairs of one segment: one translation on both sides of a split, or two.
#include <gtest/gtest.h>

#include <random>

#include "stages/foundation/se3.hpp"
#include "stages/handeye/split_test.hpp"
#include "stages/handeye/synthetic_motions.hpp"
#include "tests/support/turn_pair.hpp"

namespace fusecal {
namespace {

constexpr double kRotationNoiseDeg = 0.02;
constexpr double kTranslationNoiseM = 0.0005;

// Eight metric pairs with random axes (10-30 deg), the camera shifted by `shift` in the LiDAR frame during
// pair 4 (no shift: one extrinsic), at `noise_scale` times the noise above.
ChangingMotionSet Pairs(uint32_t seed, const Eigen::Vector3d& shift, double noise_scale = 1.0) {
  SyntheticMotionSettings s;
  s.num_motions = 8;
  s.min_angle_deg = 10;
  s.max_angle_deg = 30;
  s.rotation_noise_deg = noise_scale * kRotationNoiseDeg;
  s.translation_noise_m = noise_scale * kTranslationNoiseM;
  s.seed = seed;
  Isometry3 delta = Isometry3::Identity();
  delta.translation() = shift;
  return GenerateChangingMotions(s, shift.norm() > 0 ? 4 : -1, delta);
}

HandEyeSettings Nominal() {
  HandEyeSettings solver;
  solver.nominal_rotation_sigma_deg = kRotationNoiseDeg;
  solver.nominal_translation_sigma_m = kTranslationNoiseM;
  return solver;
}

const std::vector<int> kEveryPair{0, 1, 2, 3, 4, 5, 6, 7};

TEST(SplitTest, FindsATranslationOfTheCameraAcrossThePairThatSpansIt) {
  for (uint32_t seed = 1; seed <= 5; ++seed) {
    const ChangingMotionSet set = Pairs(seed, {0.015, -0.01, 0.008});
    const SplitTest split = TestSplits(set.pairs, kEveryPair, set.before, Nominal(), 1e-3, 6);
    EXPECT_TRUE(split.change) << "seed " << seed << ": probability " << split.probability;
    EXPECT_EQ(split.across, 4) << "seed " << seed;
    EXPECT_EQ(split.change_dof, 3);
    EXPECT_EQ(split.candidates, 6);  // the first and the last pair have no side
  }
}

TEST(SplitTest, OneExtrinsicIsAChangeAtMostAsOftenAsDesigned) {
  // At alpha = 0.05 over 200 sessions of one extrinsic, at the nominal noise and at ten times it: the noise's
  // scale is estimated from the split fits, so it does not change the rate (Bonferroni keeps it below alpha).
  for (const double noise_scale : {1.0, 10.0}) {
    int changes = 0;
    for (uint32_t seed = 1; seed <= 200; ++seed) {
      const ChangingMotionSet set = Pairs(seed, Eigen::Vector3d::Zero(), noise_scale);
      changes += TestSplits(set.pairs, kEveryPair, set.before, Nominal(), 0.05, 6).change;
    }
    EXPECT_LE(changes, 14) << "noise x" << noise_scale;  // 10 expected at most; 14 is 1.3 sigma above
    EXPECT_GE(changes, 1) << "noise x" << noise_scale << ": the test never fires, so it tests nothing";
  }
}

TEST(SplitTest, ABadPairIsNotAChange) {
  // One camera motion 5 cm off: across the split it belongs to neither side; elsewhere its side does not fit
  // one translation, which both fits of the split share.
  int changes = 0;
  for (uint32_t seed = 1; seed <= 20; ++seed) {
    ChangingMotionSet set = Pairs(seed, Eigen::Vector3d::Zero());
    set.pairs[3].A.translation() += Eigen::Vector3d(0.05, 0, 0);
    const SplitTest split = TestSplits(set.pairs, {3}, set.before, Nominal(), 1e-3, 6);
    changes += split.change;
  }
  EXPECT_EQ(changes, 0);
}

TEST(SplitTest, TurnsAboutOneAxisLeaveTheTranslationAlongItOutOfTheChange) {
  // Before the split the LiDAR turns about its z axis only, which leaves t_z free there: of a shift along z
  // nothing is seen, and the change has two directions.
  Isometry3 X = Isometry3::Identity();
  X.linear() = ExpSO3(Eigen::Vector3d(0.3, -1.2, 0.4));
  X.translation() = Eigen::Vector3d(0.05, 0.1, -0.02);
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), z = Eigen::Vector3d::UnitZ();
  for (const double shift_z : {0.0, 0.03}) {
    std::mt19937 rng(4);
    Isometry3 X_after = X;
    X_after.translation() += X.linear() * Eigen::Vector3d(0, 0, shift_z);
    const std::vector<MotionPair> pairs{
        Turn(0, z, 17, {0.2, -0.1, 0.05}, X, X, rng),
        Turn(1, z, -23, {-0.1, 0.3, -0.1}, X, X, rng),
        Turn(2, z, 20, {0.15, 0.05, 0.1}, X, X, rng),
        Turn(3, Eigen::Vector3d(2, 1, 2), 17, {0.05, 0, 0.1}, X, X_after, rng),  // across the split
        Turn(4, x, 17, {0.0, 0.2, -0.1}, X_after, X_after, rng),
        Turn(5, Eigen::Vector3d(0, 3, 1), 18, {0.1, 0, 0.2}, X_after, X_after, rng),
        Turn(6, Eigen::Vector3d(1, -3, 0), -18, {-0.2, 0.1, 0}, X_after, X_after, rng)};
    const SplitTest split = TestSplits(pairs, {3}, X, Nominal(), 1e-3, 6);
    EXPECT_EQ(split.change_dof, 2);
    EXPECT_FALSE(split.change) << "a shift of " << shift_z << " m along the only turn axis";
  }
}

}  // namespace
}  // namespace fusecal
