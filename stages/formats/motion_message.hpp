// motion_t builders shared by the nodes that publish motions.
#pragma once

#include <string>

#include "fusecal/motion_t.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal {

// A valid motion of `sensor` ("lidar" or "camera") between stations i and j.
motion_t MakeMotion(int station_i, int station_j, const std::string& sensor, const Isometry3& T_i_j, bool scaled,
                    const Matrix6& covariance, int64_t utime);

// A failed motion: never used as a good one; `reason` says why.
motion_t MakeFailedMotion(int station_i, int station_j, const std::string& sensor, const std::string& reason,
                          int64_t utime);

}  // namespace fusecal
