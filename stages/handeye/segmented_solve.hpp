// Offline change detection: a sequence of motion pairs (rows of a motion CSV, in time order) split where
// the extrinsic changed, and each part solved on its own. The same test and rule as the calibration loop
// (handeye/change_detection.hpp): each pair is tested against the solve of the pairs of its part before
// it; the pair that spans a change belongs to no part.
#pragma once

#include <functional>
#include <vector>

#include "stages/handeye/change_detection.hpp"
#include "stages/handeye/handeye_types.hpp"

namespace fusecal {

struct PairSegment {
  int first = 0;  // indices into the pairs, inclusive
  int last = -1;
  HandEyeResult result;  // the solve of pairs[first..last]
};

struct SegmentedSolve {
  std::vector<PairSegment> segments;  // one more than changes
  std::vector<ExtrinsicChange> changes;
  std::vector<int> change_pairs;  // per change: the index of the pair that spans it
};

using PairSolver = std::function<HandEyeResult(const std::vector<MotionPair>&)>;

// `solve` solves a part (SolveScaled, SolveScaleless, SolveGlobalScale). Pairs whose camera translation
// is not metric are tested by their rotation only. A part is tested against once it has `min_pairs`.
SegmentedSolve SolveWithChanges(const std::vector<MotionPair>& pairs, const PairSolver& solve,
                                const ChangeDetectionSettings& settings, const HandEyeSettings& solver);

}  // namespace fusecal
