// Outlier rejection that cannot cascade (HandEyeSettings, "Robust estimation"). The limits come from the
// residuals of every screened pair, those already set aside included, and never fall below what the
// nominal noise gives: setting a pair aside does not lower them, and a pair set aside comes back when a
// better estimate explains it.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "stages/handeye/handeye_types.hpp"
#include "stages/handeye/pair_model.hpp"

namespace fusecal::handeye {

// The pairs a solve uses (input indices, ascending, and copies) and those set aside as outliers.
struct PairSet {
  std::vector<int> index;
  std::vector<MotionPair> pairs;
  std::map<int, std::string> outliers;  // input index -> why

  int size() const { return static_cast<int>(pairs.size()); }
  void SetAside(int k, std::string why);
  void Restore(int input_index, const std::vector<MotionPair>& input);
};

// Residual magnitudes of a pair at the current estimate: rotation (degrees), translation (metres).
using PairResiduals = std::function<std::pair<double, double>(const MotionPair&)>;

// One step: sets aside the used pair furthest beyond the limits, else restores the pair set aside that is
// furthest below 0.8 x them. False when nothing changed (or fewer than 3 pairs in all).
bool RejectOrRestoreOne(PairSet* set, const std::vector<MotionPair>& input, const PairResiduals& residuals,
                        const NoiseModel& nominal, const HandEyeSettings& settings);

}  // namespace fusecal::handeye
