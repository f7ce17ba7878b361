// Rotation noise by class of motion (handeye/rotation_noise.hpp): a LiDAR that errs more across its spin
// axis when it turns than when it tilts gets that difference, and too few motions give no estimate.
#include <gtest/gtest.h>

#include <cmath>

#include "stages/foundation/se3.hpp"
#include "stages/handeye/rotation_noise.hpp"

namespace fusecal::handeye {
namespace {

// A pair at R = I whose camera rotation differs from the LiDAR's by `error` (LiDAR frame).
MotionPair PairAbout(const Eigen::Vector3d& rotation, const Eigen::Vector3d& error) {
  MotionPair p;
  p.B.linear() = ExpSO3(rotation);
  p.A.linear() = p.B.linear() * ExpSO3(error);
  return p;
}

std::vector<MotionPair> TurnsAndTilts(double turn_x_error, double tilt_x_error) {
  std::vector<MotionPair> pairs;
  for (int k = 0; k < 6; ++k) {
    const double sign = k % 2 ? 1.0 : -1.0, angle = 0.3 + 0.05 * k;
    pairs.push_back(PairAbout({0, 0, angle}, {sign * turn_x_error, -sign * 1e-4, 2e-4}));
    pairs.push_back(PairAbout({0, angle, 0}, {sign * tilt_x_error, 3e-4, -sign * 1e-4}));
  }
  return pairs;
}

TEST(RotationNoiseByAxis, TurnsThatErrMoreAcrossTheirAxisGetTheLargerVariance) {
  const auto noise = EstimateRotationNoiseByAxis(TurnsAndTilts(2e-3, 1e-4), Eigen::Matrix3d::Identity(), 1e-14);
  ASSERT_TRUE(noise.has_value());
  // Column c: motions about axis c. x across turns (about z) against x across tilts (about y).
  EXPECT_GT(noise->across_variance(0, 2), 5.0 * noise->across_variance(0, 1));
  // The angle's error (along the axis) is kept apart: 2e-4 for turns, 3e-4 for tilts.
  EXPECT_NEAR(std::sqrt(noise->axial_variance), std::sqrt((4e-8 + 9e-8) / 2), 1e-5);
}

TEST(RotationNoiseByAxis, CovarianceOfATurnIsLargestAcrossItsAxisWhereTurnsErr) {
  const auto noise = EstimateRotationNoiseByAxis(TurnsAndTilts(2e-3, 1e-4), Eigen::Matrix3d::Identity(), 1e-14);
  ASSERT_TRUE(noise.has_value());
  const Eigen::Matrix3d turn = RotationResidualCovariance(PairAbout({0, 0, 0.4}, Eigen::Vector3d::Zero()), *noise);
  const Eigen::Matrix3d tilt = RotationResidualCovariance(PairAbout({0, 0.4, 0}, Eigen::Vector3d::Zero()), *noise);
  EXPECT_GT(turn(0, 0), 5.0 * tilt(0, 0));
  EXPECT_TRUE(turn.allFinite() && tilt.allFinite());
}

TEST(RotationNoiseByAxis, FewerThanThreeMotionsGiveNoEstimate) {
  std::vector<MotionPair> pairs = TurnsAndTilts(1e-3, 1e-3);
  pairs.resize(2);
  EXPECT_FALSE(EstimateRotationNoiseByAxis(pairs, Eigen::Matrix3d::Identity(), 1e-14).has_value());
}

}  // namespace
}  // namespace fusecal::handeye
