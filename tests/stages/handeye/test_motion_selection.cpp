// Unit tests of SelectInformativePairs: which motion pairs a bounded hand-eye pool keeps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

#include "stages/handeye/motion_selection.hpp"

namespace fusecal {
namespace {

constexpr double kSigmaDeg = 0.1;

const Eigen::Vector3d kX = Eigen::Vector3d::UnitX();
const Eigen::Vector3d kY = Eigen::Vector3d::UnitY();
const Eigen::Vector3d kZ = Eigen::Vector3d::UnitZ();

// A fixed, non-trivial extrinsic, so that camera and LiDAR axes differ as in real data.
Isometry3 Extrinsic() { return MakeIsometry(RotationFromRpy(0.3, -0.2, 1.1), Eigen::Vector3d(0.1, -0.2, 0.05)); }

// LiDAR motion: `lidar_deg` about `axis` (LiDAR frame) plus a translation. Camera motion: X B' X^-1 with B'
// turning by lidar_deg + camera_extra_deg about the same axis (extra != 0: the two angles disagree).
MotionPair Pair(int station_j, const Eigen::Vector3d& axis, double lidar_deg, double camera_extra_deg = 0.0) {
  const double kDeg = M_PI / 180.0;
  const Eigen::Vector3d t(0.4, -0.3, 0.2);
  const Isometry3 X = Extrinsic();
  MotionPair p;
  p.station_i = station_j - 1;
  p.station_j = station_j;
  p.B = MakeIsometry(ExpSO3(axis.normalized() * lidar_deg * kDeg), t);
  p.A = X * MakeIsometry(ExpSO3(axis.normalized() * (lidar_deg + camera_extra_deg) * kDeg), t) * X.inverse();
  return p;
}

std::vector<int> AllIndices(size_t n) {
  std::vector<int> v(n);
  std::iota(v.begin(), v.end(), 0);
  return v;
}

bool Contains(const std::vector<int>& v, int x) { return std::find(v.begin(), v.end(), x) != v.end(); }

TEST(MotionSelection, PoolNotAboveMaxKeepsAllPairs) {
  const std::vector<MotionPair> pairs = {Pair(1, kZ, 5.0), Pair(2, kZ, 5.0), Pair(3, kX, 40.0), Pair(4, kZ, 1.0)};
  EXPECT_EQ(SelectInformativePairs(pairs, 4, kSigmaDeg), AllIndices(4));
  EXPECT_EQ(SelectInformativePairs(pairs, 100, kSigmaDeg), AllIndices(4));
  EXPECT_TRUE(SelectInformativePairs({}, 3, kSigmaDeg).empty());
}

TEST(MotionSelection, MaxPairsBelowTwoIsTreatedAsTwo) {
  const std::vector<MotionPair> pairs = {Pair(1, kZ, 30.0), Pair(2, kX, 30.0), Pair(3, kZ, 10.0)};
  for (int max_pairs : {-1, 0, 1, 2}) {
    // The two pairs about different axes are the informative ones.
    EXPECT_EQ(SelectInformativePairs(pairs, max_pairs, kSigmaDeg), (std::vector<int>{0, 1})) << max_pairs;
  }
  const std::vector<MotionPair> two = {Pair(1, kZ, 30.0), Pair(2, kZ, 30.0)};
  EXPECT_EQ(SelectInformativePairs(two, 1, kSigmaDeg), AllIndices(2));
}

TEST(MotionSelection, FewPairsAboutSecondAxisSurviveManyAboutFirst) {
  // The x pairs are the oldest and the fewest: keeping the newest, or a random subset, would lose them.
  std::vector<MotionPair> pairs;
  for (int j = 1; j <= 3; ++j) pairs.push_back(Pair(j, kX, 30.0));
  for (int j = 4; j <= 23; ++j) pairs.push_back(Pair(j, kZ, 30.0));
  const int max_pairs = 8;
  const std::vector<int> kept = SelectInformativePairs(pairs, max_pairs, kSigmaDeg);
  ASSERT_EQ(kept.size(), static_cast<size_t>(max_pairs));
  EXPECT_TRUE(std::is_sorted(kept.begin(), kept.end()));
  EXPECT_TRUE(Contains(kept, 0) && Contains(kept, 1) && Contains(kept, 2));
  // Ties among the z pairs drop the oldest, so the newest five remain.
  EXPECT_EQ(kept, (std::vector<int>{0, 1, 2, 18, 19, 20, 21, 22}));
}

TEST(MotionSelection, LargerRotationsArePreferredAboutTheSameAxis) {
  // One axis only: eps in log det(S + eps I) still ranks the pairs by their rotation.
  const std::vector<double> angles = {10.0, 40.0, 15.0, 35.0, 20.0, 30.0, 5.0};
  std::vector<MotionPair> pairs;
  for (size_t k = 0; k < angles.size(); ++k) pairs.push_back(Pair(static_cast<int>(k) + 1, kZ, angles[k]));
  EXPECT_EQ(SelectInformativePairs(pairs, 3, kSigmaDeg), (std::vector<int>{1, 3, 5}));

  // The same with a second axis present: the small z rotations go, the x pair stays.
  pairs.push_back(Pair(100, kX, 20.0));
  EXPECT_EQ(SelectInformativePairs(pairs, 4, kSigmaDeg), (std::vector<int>{1, 3, 5, 7}));
}

TEST(MotionSelection, PairWhoseAnglesDisagreeIsDroppedBeforeConsistentTwin) {
  // Identical LiDAR motions; the newer one's camera angle is 10 sigma off. By age alone the older one would go.
  const std::vector<MotionPair> pairs = {Pair(1, kZ, 30.0), Pair(2, kZ, 30.0, 10.0 * kSigmaDeg), Pair(3, kX, 30.0),
                                         Pair(4, kY, 30.0)};
  EXPECT_EQ(SelectInformativePairs(pairs, 3, kSigmaDeg), (std::vector<int>{0, 2, 3}));
  // Its information is down-weighted by 1 / (1 + 10^2).
  const double ratio =
      PairRotationInformation(pairs[1], kSigmaDeg).norm() / PairRotationInformation(pairs[0], kSigmaDeg).norm();
  EXPECT_NEAR(ratio, 1.0 / 101.0, 1e-9);
}

TEST(MotionSelection, NonFinitePairIsDroppedFirst) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int corruption = 0; corruption < 3; ++corruption) {
    // The corrupted pair is the newest and the largest rotation about an axis nobody else covers; the oldest
    // pair has no rotation, so it carries no information either and would go first on a tie.
    std::vector<MotionPair> pairs = {Pair(1, kZ, 0.0), Pair(2, kZ, 6.0), Pair(3, kX, 7.0), Pair(4, kY, 80.0)};
    if (corruption == 0) pairs[3].A.translation().x() = nan;  // rotation blocks intact
    if (corruption == 1) pairs[3].B.matrix()(0, 0) = nan;
    if (corruption == 2) pairs[3].A.matrix()(1, 2) = std::numeric_limits<double>::infinity();
    EXPECT_EQ(SelectInformativePairs(pairs, 3, kSigmaDeg), (std::vector<int>{0, 1, 2})) << corruption;
    EXPECT_TRUE(PairRotationInformation(pairs[3], kSigmaDeg).isZero()) << corruption;
  }
}

TEST(MotionSelection, TiesDropTheOldestStation) {
  // Equally informative pairs, stored out of station order: the lowest station_j goes first.
  const std::vector<int> stations = {5, 3, 9, 1, 7};
  std::vector<MotionPair> pairs;
  for (int j : stations) pairs.push_back(Pair(j, kZ, 30.0));
  EXPECT_EQ(SelectInformativePairs(pairs, 3, kSigmaDeg), (std::vector<int>{0, 2, 4}));  // stations 5, 9, 7
  EXPECT_EQ(SelectInformativePairs(pairs, 2, kSigmaDeg), (std::vector<int>{2, 4}));     // stations 9, 7
}

}  // namespace
}  // namespace fusecal
