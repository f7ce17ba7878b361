// Free-space consistency of a registration: scan i saw the space between its sensor and each of its
// returns as empty, so after a correct alignment few points of scan j lie in that space (moving objects
// and mixed pixels aside). Two unrelated scans put many points there, even when ICP found an alignment
// with a plausible inlier ratio (floors match everywhere). Used to accept or reject, and to rank the
// global candidates.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "stages/foundation/se3.hpp"

namespace fusecal::lidar_icp {

class FreeSpaceImage {
 public:
  // Spherical range image of the target's points (its own frame), `bin_deg` square bins holding the
  // smallest range seen in the bin.
  explicit FreeSpaceImage(const std::vector<Eigen::Vector3f>& target_points, double bin_deg = 0.5);

  // Share of source points (mapped by T into the target frame, range >= min_range_m) that the target
  // saw through: the target's range in their direction (smallest over the 3x3 neighbouring bins)
  // exceeds theirs by more than margin_m + 2 %. Points in directions the target has no return for are
  // not counted.
  double ViolationRatio(const std::vector<Eigen::Vector3f>& source, const Isometry3& T_target_source,
                        double min_range_m, double margin_m) const;

 private:
  int Bin(const Eigen::Vector3f& p, int* row, int* col) const;
  double bin_rad_;
  int rows_, cols_;
  std::vector<float> min_range_;  // +inf where empty
};

}  // namespace fusecal::lidar_icp
