#include "stages/handeye/split_test.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "stages/handeye/change_detection.hpp"
#include "stages/handeye/pair_model.hpp"

namespace fusecal {

namespace {

// The whitened translation rows W (R_a - I) t = W (R t_b - t_a) of one pair; not usable when not finite.
struct PairRows {
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  Eigen::Vector3d y = Eigen::Vector3d::Zero();
  bool usable = false;
};

PairRows RowsOf(const MotionPair& pair, const Isometry3& X, const handeye::NoiseModel& noise) {
  const Eigen::Matrix3d R = X.linear();
  const Matrix6 C = handeye::ResidualCovariance(pair, R, X.translation(), noise);
  const Eigen::Matrix3d W = handeye::WhiteningMatrix(C.bottomRightCorner<3, 3>());
  PairRows rows;
  // r_t = (R_a - I) t + t_a - R t_b: its Jacobian in t, and its value at t = 0 is -y.
  rows.M = W * handeye::JacobianWrtExtrinsic(pair, R).bottomRightCorner<3, 3>();
  rows.y = -W * handeye::TranslationResidual(pair, R, Eigen::Vector3d::Zero());
  rows.usable = rows.M.allFinite() && rows.y.allFinite();
  return rows;
}

struct Fit {
  double rss = 0;
  int rank = 0;
  int rows = 0;
};

// Least squares of one t over the usable pairs of [first, last) but `skip`, over the directions whose std
// (1 / singular value of the whitened rows) is at most max_std_m.
Fit FitTranslation(const std::vector<PairRows>& pairs, int first, int last, int skip, double max_std_m) {
  Fit fit;
  for (int k = first; k < last; ++k) fit.rows += (k != skip && pairs[k].usable) ? 3 : 0;
  if (fit.rows == 0) return fit;
  Eigen::MatrixXd M(fit.rows, 3);
  Eigen::VectorXd y(fit.rows);
  int row = 0;
  for (int k = first; k < last; ++k) {
    if (k == skip || !pairs[k].usable) continue;
    M.middleRows<3>(row) = pairs[k].M;
    y.segment<3>(row) = pairs[k].y;
    row += 3;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeThinU | Eigen::ComputeThinV);
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  for (int i = 0; i < svd.singularValues().size(); ++i) {
    const double s = svd.singularValues()(i);
    if (!(s * max_std_m >= 1.0)) continue;
    t += svd.matrixV().col(i) * (svd.matrixU().col(i).dot(y) / s);
    ++fit.rank;
  }
  fit.rss = (M * t - y).squaredNorm();
  return fit;
}

}  // namespace

SplitTest TestSplits(const std::vector<MotionPair>& pairs, const std::vector<int>& candidates, const Isometry3& X,
                     const HandEyeSettings& solver, double alpha, int min_noise_dof) {
  const handeye::NoiseModel noise = handeye::NominalNoise(solver);
  std::vector<PairRows> rows;
  rows.reserve(pairs.size());
  for (const MotionPair& p : pairs) rows.push_back(RowsOf(p, X, noise));
  const int n = static_cast<int>(pairs.size());
  const double max_std = solver.max_translation_std_m;
  SplitTest best;
  double best_tail = 1.0;
  for (const int k : candidates) {
    if (k <= 0 || k >= n - 1 || !rows[k].usable) continue;  // a side would be empty
    const Fit one = FitTranslation(rows, 0, n, k, max_std);
    const Fit before = FitTranslation(rows, 0, k, -1, max_std);
    const Fit after = FitTranslation(rows, k + 1, n, -1, max_std);
    const int p = before.rank + after.rank - one.rank;
    const int nu = one.rows - before.rank - after.rank;
    const double rss_split = before.rss + after.rss;
    if (p <= 0 || nu < min_noise_dof || !(rss_split > 0)) continue;
    const double F = std::max(0.0, (one.rss - rss_split) / p) / (rss_split / nu);
    const double tail = FUpperTail(p, nu, F);
    ++best.candidates;
    if (best.across < 0 || tail < best_tail) {
      best_tail = tail;
      best.across = k;
      best.statistic = F;
      best.change_dof = p;
      best.noise_dof = nu;
    }
  }
  best.probability = std::min(1.0, best_tail * best.candidates);
  best.change = best.across >= 0 && best.probability < alpha;
  return best;
}

}  // namespace fusecal
