// Bounding the hand-eye motion pool: which motion pairs to keep when there are more than a solve should use.
//
// Rule. The rotation constraint of Ishikawa et al. (IROS 2018, III-A) is k_a = R k_b: the rotation axis of
// the camera motion is the LiDAR axis rotated by the extrinsic. A pair whose LiDAR motion turns by theta (rad)
// about the unit axis k therefore fixes R only perpendicular to k (a perturbation of R about k leaves R k
// unchanged), and the axis is known to about sigma / theta. Its information on the extrinsic rotation (LiDAR
// frame, common factor 1 / sigma^2 dropped) is
//   I_i = w_i * theta_i^2 * (I - k_i k_i^T),   w_i = 1 / (1 + (d_i / sigma)^2),
// where d_i = |angle(A_i) - angle(B_i)| (rad). The angle is invariant under conjugation (R_a = R R_b R^T), so
// d_i does not depend on the unknown extrinsic; a pair whose two angles disagree has at least one wrong
// motion and is down-weighted. sigma = nominal_rotation_sigma_deg in radians.
//
// The kept set maximises log det(sum_{kept} I_i + eps I), eps = kSelectionEpsilon, greedily by backward
// elimination: starting from all pairs, the pair whose removal lowers log det the least is removed, until
// max_pairs remain. eps keeps log det finite when the kept axes span fewer than three directions, so a pool
// about a single axis still ranks pairs by the magnitude of their rotation.
//   * Ties (log det within kSelectionTieTolerance) remove the pair with the lowest station_j (the oldest),
//     then the lowest index, so the pool keeps the newest motions when they are equally informative.
//   * Pairs with non-finite entries in A or B carry no information and are removed before any other.
//   * max_pairs < 2 is treated as 2: a hand-eye solve needs two pairs about non-parallel axes.
//   * sigma that is not a positive finite number disables the down-weighting (w = 1).
// Cost: O(n^2) 3x3 determinants for a pool of n pairs (fine for the few hundred pairs a session collects).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "stages/handeye/handeye_types.hpp"

namespace fusecal {

inline constexpr double kSelectionEpsilon = 1e-9;
inline constexpr double kSelectionTieTolerance = 1e-9;

// Information I_i of one pair on the extrinsic rotation (see above); zero when A or B has non-finite entries.
Eigen::Matrix3d PairRotationInformation(const MotionPair& pair, double nominal_rotation_sigma_deg);

// Which pairs to keep when a pool holds more than `max_pairs` (the rule above).
// Returns the indices (into `pairs`, ascending) of the pairs to keep; all indices when pairs.size() <= max_pairs.
std::vector<int> SelectInformativePairs(const std::vector<MotionPair>& pairs, int max_pairs,
                                        double nominal_rotation_sigma_deg);

}  // namespace fusecal
