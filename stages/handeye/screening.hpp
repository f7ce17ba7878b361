// Screening of motion pairs: input validity, rotation-angle agreement, residual outliers.
#pragma once

#include <string>
#include <vector>

#include "handeye/handeye_types.hpp"

namespace fusecal::handeye {

struct ScreeningOutcome {
  std::vector<int> usable;  // indices into the input
  std::vector<RejectedPair> rejected;
};

// Rejects, with a reason: non-finite or non-orthonormal A or B, invalid covariances, camera motions without
// scale when `require_scaled_camera`, pairs without rotation (both angles < min_rotation_deg), and pairs whose
// rotation angles differ by more than max_angle_difference_deg (the angle is invariant under conjugation,
// R_a = R R_b R^T, so a mismatch means at least one of the two motions is wrong).
ScreeningOutcome ScreenPairs(const std::vector<MotionPair>& pairs, const HandEyeSettings& settings,
                             bool require_scaled_camera);

// Index (into the vectors) of the pair to reject as a residual outlier, or -1. A pair is an outlier when its
// rotation residual exceeds max(outlier_factor * median, outlier_min_rotation_deg) or its translation
// residual exceeds max(outlier_factor * median, outlier_min_translation_m); of several, the one exceeding its
// threshold by the largest ratio. Needs at least 3 pairs.
int FindResidualOutlier(const std::vector<double>& rot_residual_deg, const std::vector<double>& trans_residual_m,
                        const HandEyeSettings& settings, std::string* reason);

RejectedPair MakeRejected(const std::vector<MotionPair>& pairs, int index, std::string reason);

}  // namespace fusecal::handeye
