// A change-point test over the pairs of one segment, for the pairs the pair-by-pair test could not test
// (handeye/change_detection.hpp): while the estimate is rotation-degenerate (the first motions all turned
// about one axis), new pairs are tested against the scaleless estimate on their rotations alone, so a
// translation change among them would go unseen. Once the estimate is observable, the metric pairs are
// split in time and each side fitted on its own (Chow's test):
//
// With the rotation R of the estimate fixed, the translation rows of the paper's A X = X B,
//   (R_a - I) t = R t_b - t_a                       (metric camera motions; handeye/pair_model.hpp),
// each pair's rows whitened by its covariance at the solver's nominal noise, are fitted by one t over all
// pairs but the one across the split (RSS_0), and by one t on each side of it (RSS_1 = RSS_before +
// RSS_after). A side determines the directions of t whose std at the nominal noise is at most the
// verdict's max_translation_std_m (its rank; a turn about one axis leaves t along the axis free). With the
// ranks r_0, r_before, r_after, p = r_before + r_after - r_0 directions of a change are seen, and
//   F = ((RSS_0 - RSS_1) / p) / (RSS_1 / nu),   nu = rows - r_before - r_after,
// is F(p, nu) distributed when one t fits both sides. The noise's scale cancels (RSS_1 estimates it), so a
// noise unlike the nominal leaves the false-alarm rate as designed; its shape (the weights) does not. The pair
// across the split belongs to neither fit: a pair that spans a change mixes both extrinsics, and an outlier
// there cannot make a change either.
//
// Rule: a change across the candidate pair whose F has the smallest upper-tail probability, when that
// probability times the number of candidates tested (Bonferroni) is below alpha, and nu is at least
// min_noise_dof: the along-axis residual of one pair per side (nu = 2) is too few to estimate a noise from
// (on fused motions, unchanged sessions read tail probabilities of 1e-5 there).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "stages/handeye/handeye_types.hpp"

namespace fusecal {

struct SplitTest {
  int across = -1;         // index of the pair across the change; -1: no split could be tested
  double statistic = 0;    // F
  int change_dof = 0;      // p
  int noise_dof = 0;       // nu
  double probability = 1;  // upper-tail probability of F, times the candidates tested
  int candidates = 0;      // splits tested
  bool change = false;
};

// `pairs` in time order, metric; `candidates` the indices of the pairs that may be across the change; X the
// estimate (its rotation is held, its translation sets the lever arm of the rows' covariance).
SplitTest TestSplits(const std::vector<MotionPair>& pairs, const std::vector<int>& candidates, const Isometry3& X,
                     const HandEyeSettings& solver, double alpha, int min_noise_dof);

}  // namespace fusecal
