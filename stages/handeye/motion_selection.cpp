#include "stages/handeye/motion_selection.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>

namespace fusecal {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Down-weighting of pairs whose camera and LiDAR rotation angles disagree by d (rad).
double AngleAgreementWeight(double d, double sigma_rad) {
  if (!std::isfinite(sigma_rad) || sigma_rad <= 0.0) return 1.0;
  const double r = d / sigma_rad;
  return 1.0 / (1.0 + r * r);
}

// nullopt for a pair that must count as carrying no information (non-finite data), so that the selection
// can remove it before pairs that merely carry little.
std::optional<Eigen::Matrix3d> Information(const MotionPair& p, double sigma_rad) {
  if (!p.A.matrix().allFinite() || !p.B.matrix().allFinite()) return std::nullopt;
  const double theta = RotationAngle(p.B.linear());
  const Eigen::Vector3d omega = LogSO3(p.B.linear());
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  // Without rotation the axis is undefined, and theta^2 = 0 makes the information vanish anyway.
  if (omega.norm() > 0.0) {
    const Eigen::Vector3d k = omega.normalized();
    const double d = std::abs(RotationAngle(p.A.linear()) - theta);
    info = AngleAgreementWeight(d, sigma_rad) * theta * theta * (Eigen::Matrix3d::Identity() - k * k.transpose());
  }
  if (!info.allFinite()) return std::nullopt;
  return info;
}

// log det(S + eps I). S is a sum of positive semi-definite matrices, so S + eps I is positive definite.
double LogDet(const Eigen::Matrix3d& S) {
  const Eigen::LLT<Eigen::Matrix3d> llt(S + kSelectionEpsilon * Eigen::Matrix3d::Identity());
  if (llt.info() != Eigen::Success) return -kInf;
  return 2.0 * llt.matrixLLT().diagonal().array().log().sum();
}

// For each kept pair, log det of the kept information without it (+inf for a pair without information, so
// that it goes first). The sums without a pair are prefix + suffix rather than total - I_i, so that no
// cancellation can leave a spurious residue along a direction only that pair constrained.
std::vector<double> RemovalScores(const std::vector<Eigen::Matrix3d>& info, const std::vector<bool>& usable,
                                  const std::vector<int>& kept) {
  const size_t n = kept.size();
  std::vector<Eigen::Matrix3d> suffix(n + 1, Eigen::Matrix3d::Zero());
  for (size_t k = n; k-- > 0;) suffix[k] = suffix[k + 1] + info[kept[k]];
  std::vector<double> scores(n);
  Eigen::Matrix3d prefix = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < n; ++k) {
    scores[k] = usable[kept[k]] ? LogDet(prefix + suffix[k + 1]) : kInf;
    prefix += info[kept[k]];
  }
  return scores;
}

// Position in `kept` of the pair to remove: highest score; within the tie tolerance the lowest station_j,
// then the lowest index (kept is ascending, hence the strict comparison).
size_t PickRemoval(const std::vector<double>& scores, const std::vector<int>& kept,
                   const std::vector<MotionPair>& pairs) {
  const double best = *std::max_element(scores.begin(), scores.end());
  size_t pick = kept.size();
  for (size_t k = 0; k < kept.size(); ++k) {
    if (scores[k] < best - kSelectionTieTolerance) continue;
    if (pick == kept.size() || pairs[kept[k]].station_j < pairs[kept[pick]].station_j) pick = k;
  }
  return pick;
}

}  // namespace

Eigen::Matrix3d PairRotationInformation(const MotionPair& pair, double nominal_rotation_sigma_deg) {
  return Information(pair, nominal_rotation_sigma_deg * kDegToRad).value_or(Eigen::Matrix3d::Zero());
}

std::vector<int> SelectInformativePairs(const std::vector<MotionPair>& pairs, int max_pairs,
                                        double nominal_rotation_sigma_deg) {
  const size_t target = static_cast<size_t>(std::max(max_pairs, 2));
  std::vector<int> kept(pairs.size());
  std::iota(kept.begin(), kept.end(), 0);
  if (kept.size() <= target) return kept;

  std::vector<Eigen::Matrix3d> info(pairs.size());
  std::vector<bool> usable(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    const auto I_i = Information(pairs[i], nominal_rotation_sigma_deg * kDegToRad);
    usable[i] = I_i.has_value();
    info[i] = I_i.value_or(Eigen::Matrix3d::Zero());
  }
  while (kept.size() > target) {
    const std::vector<double> scores = RemovalScores(info, usable, kept);
    kept.erase(kept.begin() + static_cast<std::ptrdiff_t>(PickRemoval(scores, kept, pairs)));
  }
  return kept;
}

}  // namespace fusecal
