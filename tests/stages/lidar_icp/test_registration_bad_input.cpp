// Bad input gives a clear failure (not usable, a code and a reason), never a crash or an exception.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "runtime/sim/fixtures/synthetic_scans.hpp"
#include "stages/foundation/se3.hpp"
#include "stages/lidar_icp/registration.hpp"

namespace fusecal::lidar_icp {
namespace {

PointCloud RoomScan(const Isometry3& pose, uint32_t seed) {
  return fixtures::SimulateScan(fixtures::MakeRoom(), pose, fixtures::Hdl64Pattern(1000), 0.015, seed);
}

void ExpectFailure(const PointCloud& a, const PointCloud& b, const std::string& reason_part,
                   RegistrationFailure code = RegistrationFailure::kTooFewPoints) {
  RegistrationResult r;
  EXPECT_NO_THROW(r = Register(a, b));
  EXPECT_FALSE(r.usable());
  EXPECT_FALSE(r.usable());
  EXPECT_EQ(r.failure_reason.code, code);
  EXPECT_FALSE(r.failure_reason.text.empty());
  EXPECT_NE(r.failure_reason.text.find(reason_part), std::string::npos) << r.failure_reason;
  std::printf("  failure reason: %s\n", r.failure_reason.text.c_str());
}

TEST(RegistrationBadInput, EmptyScan) {
  const PointCloud room = RoomScan(Isometry3::Identity(), 1);
  ExpectFailure(PointCloud(), room, "scan i has 0 valid points");
  ExpectFailure(room, PointCloud(), "scan j has 0 valid points");
}

TEST(RegistrationBadInput, AllNaN) {
  PointCloud nan_scan;
  nan_scan.points.assign(5000, Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  ExpectFailure(RoomScan(Isometry3::Identity(), 1), nan_scan, "scan j has 0 valid points of 5000");
}

TEST(RegistrationBadInput, FewerThan100Points) {
  PointCloud room = RoomScan(Isometry3::Identity(), 1);
  PointCloud tiny;
  for (size_t i = 0; i < 99; ++i) tiny.points.push_back(room.points[i * 97]);
  ExpectFailure(room, tiny, "fewer than min_points 100");
}

TEST(RegistrationBadInput, UnrelatedScans) {
  const PointCloud a = RoomScan(Isometry3::Identity(), 1);
  const PointCloud b =
      fixtures::SimulateScan(fixtures::MakeOtherRoom(), Isometry3::Identity(), fixtures::Hdl64Pattern(1000), 0.015, 2);
  RegistrationResult r;
  EXPECT_NO_THROW(r = Register(a, b));
  EXPECT_FALSE(r.usable());
  EXPECT_NE(r.failure_reason.code, RegistrationFailure::kNone);
  EXPECT_FALSE(r.failure_reason.text.empty());
  std::printf("  unrelated scans: %s\n", r.failure_reason.text.c_str());
}

TEST(RegistrationBadInput, NaNPointsAmongValidOnesAreIgnored) {
  PointCloud a = RoomScan(Isometry3::Identity(), 1);
  const Isometry3 B = MakeIsometry(RotationFromRpy(0, 0, 0.5), Eigen::Vector3d(0.2, 0.1, 0));
  PointCloud b = RoomScan(B, 2);
  for (size_t i = 0; i < b.size(); i += 10) b.points[i].x() = std::numeric_limits<float>::quiet_NaN();
  for (size_t i = 0; i < a.size(); i += 13) a.points[i].z() = std::numeric_limits<float>::infinity();
  const RegistrationResult r = Register(a, b);
  ASSERT_TRUE(r.usable()) << r.failure_reason;
  EXPECT_EQ(r.failure_reason.code, RegistrationFailure::kNone);
  EXPECT_LT(RotationErrorDeg(r.T_li_lj.linear(), B.linear()), 0.05);
  EXPECT_LT((r.T_li_lj.translation() - B.translation()).norm(), 0.01);
}

}  // namespace
}  // namespace fusecal::lidar_icp
