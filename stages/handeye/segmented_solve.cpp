#include "stages/handeye/segmented_solve.hpp"

namespace fusecal {

namespace {

HandEyeResult SolvePart(const std::vector<MotionPair>& pairs, int first, int last, const PairSolver& solve) {
  return solve(std::vector<MotionPair>(pairs.begin() + first, pairs.begin() + last + 1));
}

}  // namespace

SegmentedSolve SolveWithChanges(const std::vector<MotionPair>& pairs, const PairSolver& solve,
                                const ChangeDetectionSettings& settings, const HandEyeSettings& solver) {
  SegmentedSolve out;
  ChangeDetector detector(settings);
  std::optional<HandEyeResult> reference;
  int start = 0;
  const int n = static_cast<int>(pairs.size());
  for (int k = 0; k < n; ++k) {
    // The reference: the part's solve before pair k, kept from before the first off pair while one is new.
    if (k - start >= std::max(2, solver.min_pairs) && !detector.Suspicious()) {
      HandEyeResult part = SolvePart(pairs, start, k - 1, solve);
      if (part.usable()) reference = std::move(part);
    }
    if (!reference) continue;
    const PairTest test = TestPair(pairs[k], *reference, solver, settings);
    const std::optional<int> after = detector.Add(test);
    if (!after) continue;
    // The pair that spans the change: the first of the part's newest pairs that starts at `after`.
    int spanning = k;
    while (spanning > start && pairs[spanning].station_i != *after) --spanning;
    out.changes.push_back({*after, pairs[k].station_j, reference->T_camera_lidar, reference->covariance});
    out.change_pairs.push_back(spanning);
    out.segments.push_back({start, spanning - 1, {}});
    start = spanning + 1;
    reference.reset();
    detector.Reset();
  }
  out.segments.push_back({start, n - 1, {}});
  for (PairSegment& s : out.segments)
    s.result = s.last >= s.first ? SolvePart(pairs, s.first, s.last, solve) : solve({});
  return out;
}

}  // namespace fusecal
