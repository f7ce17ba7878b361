// Stop-and-rotate trajectories: still while still, continuous while moving, the requested motions
// about the requested axes.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "runtime/sim/simulator/trajectory.hpp"
#include "tests/support/simulator_test_util.hpp"

namespace fusecal::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

class SimTrajectoryTest : public ::testing::Test {
 protected:
  const Scenario scenario_ = LoadScenario(testing::ScenarioPath("indoor-equirect-hdl64.yaml"));
  const Trajectory trajectory_ = BuildTrajectory(scenario_);
};

TEST_F(SimTrajectoryTest, MotionCountsMatchScenario) {
  const auto& m = trajectory_.motions();
  ASSERT_EQ(m.size(), 10u);
  ASSERT_EQ(trajectory_.stills().size(), 11u);
  int horizontal = 0, vertical = 0;
  for (const auto& motion : m) (motion.kind == Motion::Kind::kHorizontal ? horizontal : vertical)++;
  EXPECT_EQ(horizontal, 5);
  EXPECT_EQ(vertical, 5);
  for (size_t i = 0; i < trajectory_.stills().size(); ++i) {
    const auto& s = trajectory_.stills()[i];
    EXPECT_EQ(s.station_id, static_cast<int>(i));
    EXPECT_NEAR(s.t_to - s.t_from, 3.0, 1e-12);
  }
  for (const auto& motion : m) {
    EXPECT_GE(motion.t_to - motion.t_from, 2.0);
    EXPECT_LE(motion.t_to - motion.t_from, 3.0);
  }
}

TEST_F(SimTrajectoryTest, StillIntervalsAreStill) {
  for (const auto& s : trajectory_.stills()) {
    for (double f : {0.0, 0.1, 0.5, 0.9, 1.0}) {
      const double t = s.t_from + f * (s.t_to - s.t_from);
      EXPECT_TRUE(trajectory_.T_world_lidar(t).isApprox(s.T_world_lidar, 0.0)) << "station " << s.station_id;
      EXPECT_EQ(trajectory_.StillStation(t, t), s.station_id);
    }
  }
  // Mid-motion is not still, and differs from both ends.
  for (const auto& m : trajectory_.motions()) {
    const double t = 0.5 * (m.t_from + m.t_to);
    EXPECT_EQ(trajectory_.StillStation(t, t), -1);
    const Isometry3 T = trajectory_.T_world_lidar(t);
    EXPECT_GT(RotationErrorDeg(T.linear(), trajectory_.stills()[m.from_station].T_world_lidar.linear()), 1.0);
    EXPECT_GT(RotationErrorDeg(T.linear(), trajectory_.stills()[m.from_station + 1].T_world_lidar.linear()), 1.0);
  }
}

TEST_F(SimTrajectoryTest, MovesAreContinuousWithBoundedSpeed) {
  const double dt = 1e-3;
  double max_speed = 0, max_rate = 0;
  Isometry3 prev = trajectory_.T_world_lidar(0.0);
  for (double t = dt; t <= trajectory_.duration() + 1e-9; t += dt) {
    const Isometry3 T = trajectory_.T_world_lidar(t);
    max_speed = std::max(max_speed, (T.translation() - prev.translation()).norm() / dt);
    max_rate = std::max(max_rate, RotationErrorDeg(T.linear(), prev.linear()) / dt);
    prev = T;
  }
  // Minimum-jerk peak speed is 1.875 x mean: 25 deg in 2 s -> 23 deg/s; sensor speed < 0.3 m/s.
  EXPECT_LT(max_rate, 30.0);
  EXPECT_LT(max_speed, 0.5);
  EXPECT_GT(max_rate, 5.0);  // it does move
  // Each motion ends exactly at the next station.
  for (const auto& m : trajectory_.motions()) {
    const Isometry3 end = trajectory_.T_world_lidar(m.t_to - 1e-9);
    const Isometry3& next = trajectory_.stills()[m.from_station + 1].T_world_lidar;
    EXPECT_LT((end.translation() - next.translation()).norm(), 1e-6);
    EXPECT_LT(RotationErrorDeg(end.linear(), next.linear()), 1e-5);
  }
}

TEST_F(SimTrajectoryTest, RotationAxesAndAnglesAsRequested) {
  const auto& stills = trajectory_.stills();
  for (const auto& m : trajectory_.motions()) {
    const Isometry3& a = stills[m.from_station].T_world_lidar;
    const Isometry3& b = stills[m.from_station + 1].T_world_lidar;
    const Eigen::AngleAxisd rotation(b.linear() * a.linear().transpose());  // in the world frame
    const double angle_deg = rotation.angle() / kDeg;
    const double vertical_component = std::abs(rotation.axis().z());
    if (m.kind == Motion::Kind::kHorizontal) {
      EXPECT_GT(vertical_component, 1.0 - 1e-9) << "turn not about the vertical";
      EXPECT_GE(angle_deg, 10.0 - 1e-9);
      EXPECT_LE(angle_deg, 25.0 + 1e-9);
    } else {
      EXPECT_LT(vertical_component, 1e-9) << "tilt not about a horizontal axis";
      EXPECT_GE(angle_deg, 8.0 - 1e-9);
      EXPECT_LE(angle_deg, 16.0 + 1e-9);
      // The rig stays within the allowed tilt.
      EXPECT_LT(std::acos((b.linear() * Eigen::Vector3d::UnitZ()).z()) / kDeg, 16.0 + 1e-6);
    }
    // The pivot is off the sensor, so the sensor also translates (lever arm), but only a little.
    const double moved = (b.translation() - a.translation()).norm();
    EXPECT_GT(moved, 0.01);
    EXPECT_LT(moved, 0.5);
  }
}

TEST_F(SimTrajectoryTest, RigStaysInsideTheRoom) {
  for (double t = 0; t <= trajectory_.duration(); t += 0.05) {
    const Eigen::Vector3d p = trajectory_.T_world_lidar(t).translation();
    EXPECT_LT((p - scenario_.rig_position_m).head<2>().norm(), scenario_.motions.max_drift_m + 0.3);
    EXPECT_GT(p.z(), 1.0);
    EXPECT_LT(p.z(), 2.0);
  }
}

TEST_F(SimTrajectoryTest, SeedDeterminesTrajectory) {
  const Trajectory again = BuildTrajectory(scenario_);
  Scenario other = scenario_;
  other.seed += 1;
  const Trajectory different = BuildTrajectory(other);
  const double t = trajectory_.duration();
  EXPECT_TRUE(again.T_world_lidar(t).isApprox(trajectory_.T_world_lidar(t), 0.0));
  EXPECT_FALSE(different.T_world_lidar(t).isApprox(trajectory_.T_world_lidar(t), 1e-6));
}

TEST(SimTrajectory, AlternatingTiltAxesAndGroupedOrder) {
  Scenario s = LoadScenario(testing::ScenarioPath("tiny-equirect.yaml"));
  s.motions.tilt_axis = "alternate";
  s.motions.order = "grouped";
  const Trajectory tr = BuildTrajectory(s);
  ASSERT_EQ(tr.motions().size(), 4u);
  EXPECT_EQ(tr.motions()[0].kind, Motion::Kind::kHorizontal);
  EXPECT_EQ(tr.motions()[1].kind, Motion::Kind::kHorizontal);
  EXPECT_EQ(tr.motions()[2].kind, Motion::Kind::kVertical);
  EXPECT_EQ(tr.motions()[3].kind, Motion::Kind::kVertical);
  // The two tilts are about the rig's pitch and roll axes: seen from the LiDAR, about y then x.
  for (int k = 2; k < 4; ++k) {
    const auto& m = tr.motions()[k];
    const Eigen::Vector3d axis_lidar = tr.stills()[m.from_station].T_world_lidar.linear().transpose() * m.axis_world;
    EXPECT_GT(std::abs(axis_lidar[k == 2 ? 1 : 0]), 0.95) << axis_lidar.transpose();
  }
}

TEST(SimTrajectory, MinimumJerkProfile) {
  EXPECT_DOUBLE_EQ(MinimumJerk(0.0), 0.0);
  EXPECT_DOUBLE_EQ(MinimumJerk(1.0), 1.0);
  EXPECT_DOUBLE_EQ(MinimumJerk(0.5), 0.5);
  const double h = 1e-6;
  EXPECT_NEAR((MinimumJerk(h) - MinimumJerk(0)) / h, 0.0, 1e-6);  // starts and ends at rest
  EXPECT_NEAR((MinimumJerk(1) - MinimumJerk(1 - h)) / h, 0.0, 1e-6);
}

}  // namespace
}  // namespace fusecal::sim
