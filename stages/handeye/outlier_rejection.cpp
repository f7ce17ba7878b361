#include "stages/handeye/outlier_rejection.hpp"

#include <cmath>
#include <sstream>

#include "stages/handeye/screening.hpp"

namespace fusecal::handeye {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
constexpr double kRestoreBelow = 0.8;  // a margin, so that a pair does not go back and forth

std::string Why(const std::pair<double, double>& r, const ResidualLimits& limits) {
  std::ostringstream s;
  // The scaleless solve gives an infinite translation residual to a pair that needs a negative scale.
  if (!std::isfinite(r.second)) return "negative scale (camera translation direction flipped)";
  s << "residual outlier: rotation " << r.first << " deg (limit " << limits.rotation_deg << "), translation "
    << r.second << " m (limit " << limits.translation_m << ")";
  return s.str();
}

}  // namespace

void PairSet::SetAside(int k, std::string why) {
  outliers[index[k]] = std::move(why);
  index.erase(index.begin() + k);
  pairs.erase(pairs.begin() + k);
}

void PairSet::Restore(int input_index, const std::vector<MotionPair>& input) {
  outliers.erase(input_index);
  int k = 0;
  while (k < size() && index[k] < input_index) ++k;
  index.insert(index.begin() + k, input_index);
  pairs.insert(pairs.begin() + k, input[input_index]);
}

bool RejectOrRestoreOne(PairSet* set, const std::vector<MotionPair>& input, const PairResiduals& residuals,
                        const NoiseModel& nominal, const HandEyeSettings& s) {
  if (set->size() + static_cast<int>(set->outliers.size()) < 3) return false;
  std::vector<std::pair<double, double>> used, aside;
  std::vector<double> rot_deg, trans_m;
  for (const auto& p : set->pairs) used.push_back(residuals(p));
  for (const auto& [i, why] : set->outliers) aside.push_back(residuals(input[i]));
  for (const auto* group : {&used, &aside})
    for (const auto& [rot, trans] : *group) {
      rot_deg.push_back(rot);
      trans_m.push_back(std::isfinite(trans) ? trans : 0.0);
    }
  const ResidualLimits limits =
      OutlierLimits(rot_deg, trans_m, NominalMedianResidual(nominal.rot_sigma_rad) * kRadToDeg,
                    NominalMedianResidual(nominal.trans_sigma_m), s);
  int worst = -1;
  double worst_ratio = 1.0;
  for (int k = 0; k < set->size(); ++k)
    if (const double ratio = limits.Ratio(used[k].first, used[k].second); ratio > worst_ratio) {
      worst_ratio = ratio;
      worst = k;
    }
  if (worst >= 0 && set->size() > 2) {
    set->SetAside(worst, Why(used[worst], limits));
    return true;
  }
  int best = -1;
  double best_ratio = kRestoreBelow;
  int k = 0;
  for (const auto& [i, why] : set->outliers) {
    if (const double ratio = limits.Ratio(aside[k].first, aside[k].second); ratio < best_ratio) {
      best_ratio = ratio;
      best = i;
    }
    ++k;
  }
  if (best < 0) return false;
  set->Restore(best, input);
  return true;
}

}  // namespace fusecal::handeye
