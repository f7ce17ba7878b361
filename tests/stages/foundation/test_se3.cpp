#include <gtest/gtest.h>

#include "stages/foundation/se3.hpp"

namespace fusecal {
namespace {

TEST(Se3, RotationAngleIsAccurateNearZeroAndPi) {
  for (double angle : {1e-9, 1e-4, 0.3, 2.0, M_PI - 1e-6}) {
    const Eigen::Matrix3d R = ExpSO3(Eigen::Vector3d(1, 2, -0.5).normalized() * angle);
    EXPECT_NEAR(RotationAngle(R), angle, 1e-9) << angle;
  }
}

TEST(Se3, LogInvertsExp) {
  const Eigen::Vector3d omega(0.3, -1.1, 0.7);
  EXPECT_LT((LogSO3(ExpSO3(omega)) - omega).norm(), 1e-12);
}

TEST(Se3, RpyRoundTripAndConvention) {
  const Eigen::Matrix3d R = RotationFromRpy(0.1, -0.2, 0.3);
  EXPECT_LT((RpyFromRotation(R) - Eigen::Vector3d(0.1, -0.2, 0.3)).norm(), 1e-12);
  // yaw about z turns x towards y.
  EXPECT_LT((RotationFromRpy(0, 0, M_PI / 2) * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-12);
}

TEST(Se3, RowMajorRoundTrip) {
  const Isometry3 T = MakeIsometry(ExpSO3({0.1, 0.2, 0.3}), {1, -2, 3});
  double m[16];
  ToRowMajor(T, m);
  EXPECT_DOUBLE_EQ(m[3], 1.0);  // translation x is in the last column of the first row
  EXPECT_LT((FromRowMajor(m).matrix() - T.matrix()).norm(), 1e-12);
}

TEST(Se3, InvalidTransformsAreDetected) {
  Isometry3 T = Isometry3::Identity();
  EXPECT_TRUE(IsValidTransform(T));
  T.linear()(0, 1) = 0.5;
  EXPECT_FALSE(IsValidTransform(T));
  T = Isometry3::Identity();
  T.translation().x() = std::nan("");
  EXPECT_FALSE(IsValidTransform(T));
}

}  // namespace
}  // namespace fusecal
