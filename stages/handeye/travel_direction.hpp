// What motions without rotation still show (a car driving straight, a cart pushed along a corridor).
//
// With R_a = I the hand-eye translation equation R_a t + s t_a = R t_b + t (docs/design.md section 1)
// reduces to s t_a = R t_b: the direction of travel seen by both sensors. It fixes two of the three
// rotation degrees of freedom; the rotation about the direction of travel, and all of t (the term
// (R_a - I) t vanishes), stay unobserved. The rotation axes of such motions are noise.
#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "stages/handeye/handeye_types.hpp"

namespace fusecal::handeye {

struct TravelDirection {
  Eigen::Vector3d camera = Eigen::Vector3d::UnitZ();  // unit, camera frame
  Eigen::Vector3d lidar = Eigen::Vector3d::UnitX();   // unit, LiDAR frame
  double spread_deg = 0.0;                            // RMS angle between the pairs' camera directions and R lidar_i
  double largest_rotation_deg = 0.0;                  // of the pairs taken
  int pairs = 0;
};

// The common direction of the pairs that turn less than settings.min_rotation_deg (both sensors) and
// travel at least min_travel_m (LiDAR), when at least two such pairs travel along one line (within
// max_spread_deg of their mean, either way); nullopt otherwise.
std::optional<TravelDirection> FindTravelDirection(const std::vector<MotionPair>& pairs,
                                                   const HandEyeSettings& settings, double min_travel_m = 0.05,
                                                   double max_spread_deg = 10.0);

}  // namespace fusecal::handeye
