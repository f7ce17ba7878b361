// Screening of motion pairs: input validity, rotation-angle agreement, residual outliers.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "stages/handeye/handeye_types.hpp"

namespace fusecal::handeye {

struct ScreeningOutcome {
  std::vector<int> usable;  // indices into the input
  std::vector<RejectedPair> rejected;
};

// Rejects, with a reason: non-finite or non-orthonormal A or B, invalid covariances, camera motions without
// scale when `require_scaled_camera`, pairs without rotation (both angles < min_rotation_deg), and pairs whose
// rotation angles differ by more than max_angle_difference_deg + angle_difference_fraction x the larger angle
// (the angle is invariant under conjugation, R_a = R R_b R^T, so a mismatch means at least one of the two
// motions is wrong).
ScreeningOutcome ScreenPairs(const std::vector<MotionPair>& pairs, const HandEyeSettings& settings,
                             bool require_scaled_camera);

// Residual limits of the outlier rejection (HandEyeSettings, "Robust estimation"), from the residuals of
// every candidate pair: outlier_factor x median, floored at outlier_factor x the median residual the
// nominal noise gives (`nominal_median_*`) and at outlier_min_*.
struct ResidualLimits {
  double rotation_deg = 0.0;
  double translation_m = 0.0;
  // How far a pair's residuals are beyond the limits (> 1: outside).
  double Ratio(double rot_deg, double trans_m) const {
    return std::max(rot_deg / rotation_deg, trans_m / translation_m);
  }
};
ResidualLimits OutlierLimits(const std::vector<double>& rot_residual_deg, const std::vector<double>& trans_residual_m,
                             double nominal_median_rot_deg, double nominal_median_trans_m,
                             const HandEyeSettings& settings);

// Median |r| of a residual with independent per-axis noise of variance 2 sigma^2 (a pair's two motions):
// sqrt(2) sigma times the median of the chi distribution with 3 degrees of freedom (1.538).
double NominalMedianResidual(double sigma);

RejectedPair MakeRejected(const std::vector<MotionPair>& pairs, int index, std::string reason);

}  // namespace fusecal::handeye
