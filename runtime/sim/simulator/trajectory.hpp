// Stop-and-rotate rig trajectory: still, move, still, ..., still. Each move turns the rig about the
// vertical axis ("horizontal" motion, plus a small horizontal translation) or tilts it about a
// horizontal axis ("vertical" motion, like a wheel going up a step), about a pivot away from the LiDAR
// (lever arm), with a minimum-jerk profile (zero velocity and acceleration at both ends).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "runtime/sim/simulator/scenario.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal::sim {

struct StillInterval {
  int station_id;
  double t_from, t_to;  // seconds since the start
  Isometry3 T_world_lidar;
};

struct Motion {
  enum class Kind { kHorizontal, kVertical };
  Kind kind;
  int from_station;  // moves from station from_station to from_station + 1
  double t_from, t_to;
  Eigen::Vector3d axis_world;         // unit rotation axis
  Eigen::Vector3d pivot_world;        // point on the rotation axis
  double angle_rad;                   // signed, about axis_world
  Eigen::Vector3d translation_world;  // added on top of the rotation about the pivot
};

class Trajectory {
 public:
  Trajectory(std::vector<StillInterval> stills, std::vector<Motion> motions);

  // Pose of the LiDAR at time t (seconds since the start); constant before 0 and after the end.
  Isometry3 T_world_lidar(double t) const;
  double duration() const;
  // Station whose still interval contains all of [t0, t1]; -1 if none.
  int StillStation(double t0, double t1) const;

  const std::vector<StillInterval>& stills() const { return stills_; }
  const std::vector<Motion>& motions() const { return motions_; }

 private:
  std::vector<StillInterval> stills_;
  std::vector<Motion> motions_;
};

// Minimum-jerk progress 10 x^3 - 15 x^4 + 6 x^5 for x in [0, 1].
double MinimumJerk(double x);

// Draws the motions of the scenario from its seed.
Trajectory BuildTrajectory(const Scenario& scenario);

}  // namespace fusecal::sim
