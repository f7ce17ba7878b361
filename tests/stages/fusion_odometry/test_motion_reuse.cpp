// When fusion odometry keeps a pair's fused motion instead of computing it again: within the fixed
// tolerances, or within a fraction of the requesting estimate's own std.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "stages/fusion_odometry/node/fusion_odometry_node.hpp"

namespace fusecal {
namespace {

constexpr double kDeg = M_PI / 180.0;

// An observable request whose rotation std is largest about one axis (rad) and translation std largest
// along one axis (m).
extrinsic_t Request(double rotation_std_rad, double translation_std_m) {
  extrinsic_t e{};
  e.observability = extrinsic_t::OBSERVABILITY_OK;
  e.status = extrinsic_t::STATUS_REFINING;
  const double variances[6] = {std::pow(rotation_std_rad, 2),       std::pow(0.5 * rotation_std_rad, 2),
                               std::pow(0.2 * rotation_std_rad, 2), std::pow(0.3 * translation_std_m, 2),
                               std::pow(translation_std_m, 2),      std::pow(0.1 * translation_std_m, 2)};
  for (int i = 0; i < 6; ++i) e.covariance[i * 6 + i] = variances[i];
  return e;
}

TEST(FusedMotionReuse, WithinAFractionOfTheEstimatesLargestStd) {
  const FusionOdometryNodeSettings settings;  // 0.5 of the std, at least 0.001 deg / 0.1 mm
  const ReuseTolerance tolerance = FusedMotionReuseTolerance(settings, Request(0.01 * kDeg, 0.002));
  EXPECT_NEAR(tolerance.rotation_deg, 0.005, 1e-12);
  EXPECT_NEAR(tolerance.translation_m, 0.001, 1e-12);
}

TEST(FusedMotionReuse, NeverBelowTheFixedTolerances) {
  const FusionOdometryNodeSettings settings;
  const ReuseTolerance tolerance = FusedMotionReuseTolerance(settings, Request(1e-4 * kDeg, 1e-6));
  EXPECT_DOUBLE_EQ(tolerance.rotation_deg, settings.reuse_rotation_deg);
  EXPECT_DOUBLE_EQ(tolerance.translation_m, settings.reuse_translation_m);
}

TEST(FusedMotionReuse, FixedTolerancesOnlyWhenTheStdSaysNothing) {
  const FusionOdometryNodeSettings settings;
  const auto fixed = [&](const extrinsic_t& request) {
    const ReuseTolerance t = FusedMotionReuseTolerance(settings, request);
    return t.rotation_deg == settings.reuse_rotation_deg && t.translation_m == settings.reuse_translation_m;
  };
  extrinsic_t partly = Request(0.01 * kDeg, 0.002);
  partly.observability = extrinsic_t::OBSERVABILITY_TRANSLATION_PARTLY_UNOBSERVABLE;
  EXPECT_TRUE(fixed(partly));  // its std along the unobservable direction is no bound
  extrinsic_t not_a_covariance = Request(0.01 * kDeg, 0.002);
  not_a_covariance.covariance[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(fixed(not_a_covariance));
  FusionOdometryNodeSettings off = settings;
  off.reuse_std_fraction = 0;
  const ReuseTolerance t = FusedMotionReuseTolerance(off, Request(0.01 * kDeg, 0.002));
  EXPECT_DOUBLE_EQ(t.rotation_deg, settings.reuse_rotation_deg);
  EXPECT_DOUBLE_EQ(t.translation_m, settings.reuse_translation_m);
}

}  // namespace
}  // namespace fusecal
