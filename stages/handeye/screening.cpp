#include "handeye/screening.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace fusecal::handeye {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

// Empty when T is a proper rigid transform, else why not.
std::string TransformProblem(const Isometry3& T, const char* name, double tol) {
  if (!T.matrix().allFinite()) return std::string(name) + " has non-finite entries";
  const Eigen::Matrix3d R = T.linear();
  const double err = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  if (err >= tol || R.determinant() <= 0.0) {
    std::ostringstream s;
    s << name << " rotation is not orthonormal (|R^T R - I| = " << err << ", det = " << R.determinant() << ")";
    return s.str();
  }
  return {};
}

std::string CovarianceProblem(const std::optional<Matrix6>& C, const char* name) {
  if (!C) return {};
  if (!C->allFinite()) return std::string(name) + " has non-finite entries";
  if ((*C - C->transpose()).norm() > 1e-9 * std::max(1.0, C->norm()))
    return std::string(name) + " is not symmetric";
  const Eigen::SelfAdjointEigenSolver<Matrix6> eig(*C);
  if (eig.eigenvalues().minCoeff() <= 0.0) return std::string(name) + " is not positive definite";
  return {};
}

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  double m = v[v.size() / 2];
  if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + v.size() / 2));
  return m;
}

}  // namespace

RejectedPair MakeRejected(const std::vector<MotionPair>& pairs, int index, std::string reason) {
  return {index, pairs[index].station_i, pairs[index].station_j, std::move(reason)};
}

ScreeningOutcome ScreenPairs(const std::vector<MotionPair>& pairs, const HandEyeSettings& settings,
                             bool require_scaled_camera) {
  ScreeningOutcome out;
  for (int i = 0; i < static_cast<int>(pairs.size()); ++i) {
    const MotionPair& p = pairs[i];
    std::string why = TransformProblem(p.A, "camera motion A", settings.orthonormality_tolerance);
    if (why.empty()) why = TransformProblem(p.B, "LiDAR motion B", settings.orthonormality_tolerance);
    if (why.empty()) why = CovarianceProblem(p.cov_A, "cov_A");
    if (why.empty()) why = CovarianceProblem(p.cov_B, "cov_B");
    if (why.empty() && require_scaled_camera && !p.camera_scaled)
      why = "camera motion has no scale (camera_scaled = false)";
    if (why.empty()) {
      const double angle_a = RotationAngle(p.A.linear()) * kRadToDeg;
      const double angle_b = RotationAngle(p.B.linear()) * kRadToDeg;
      std::ostringstream s;
      if (std::max(angle_a, angle_b) < settings.min_rotation_deg) {
        s << "no rotation (camera " << angle_a << " deg, LiDAR " << angle_b << " deg < " << settings.min_rotation_deg
          << " deg): axis undefined";
        why = s.str();
      } else if (std::abs(angle_a - angle_b) > settings.max_angle_difference_deg) {
        s << "rotation angles disagree: camera " << angle_a << " deg, LiDAR " << angle_b << " deg (limit "
          << settings.max_angle_difference_deg << " deg)";
        why = s.str();
      }
    }
    if (why.empty())
      out.usable.push_back(i);
    else
      out.rejected.push_back(MakeRejected(pairs, i, why));
  }
  return out;
}

int FindResidualOutlier(const std::vector<double>& rot_residual_deg, const std::vector<double>& trans_residual_m,
                        const HandEyeSettings& settings, std::string* reason) {
  const size_t n = rot_residual_deg.size();
  if (n < 3 || trans_residual_m.size() != n) return -1;
  const double thr_rot = std::max(settings.outlier_factor * Median(rot_residual_deg), settings.outlier_min_rotation_deg);
  const double thr_trans =
      std::max(settings.outlier_factor * Median(trans_residual_m), settings.outlier_min_translation_m);
  int worst = -1;
  double worst_ratio = 1.0;
  for (size_t i = 0; i < n; ++i) {
    const double ratio = std::max(rot_residual_deg[i] / thr_rot, trans_residual_m[i] / thr_trans);
    if (ratio > worst_ratio) {
      worst_ratio = ratio;
      worst = static_cast<int>(i);
    }
  }
  if (worst >= 0 && reason) {
    std::ostringstream s;
    s << "residual outlier: rotation " << rot_residual_deg[worst] << " deg (limit " << thr_rot << "), translation "
      << trans_residual_m[worst] << " m (limit " << thr_trans << ")";
    *reason = s.str();
  }
  return worst;
}

}  // namespace fusecal::handeye
