#include "stages/handeye/screening.hpp"

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
  if ((*C - C->transpose()).norm() > 1e-9 * std::max(1.0, C->norm())) return std::string(name) + " is not symmetric";
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
      } else if (const double limit = settings.max_angle_difference_deg +
                                      settings.angle_difference_fraction * std::max(angle_a, angle_b);
                 std::abs(angle_a - angle_b) > limit) {
        s << "rotation angles disagree: camera " << angle_a << " deg, LiDAR " << angle_b << " deg (limit " << limit
          << " deg)";
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

ResidualLimits OutlierLimits(const std::vector<double>& rot_residual_deg, const std::vector<double>& trans_residual_m,
                             double nominal_median_rot_deg, double nominal_median_trans_m, const HandEyeSettings& s) {
  ResidualLimits limits;
  const double f = s.outlier_factor;
  limits.rotation_deg =
      std::max({f * Median(rot_residual_deg), f * nominal_median_rot_deg, s.outlier_min_rotation_deg});
  limits.translation_m =
      std::max({f * Median(trans_residual_m), f * nominal_median_trans_m, s.outlier_min_translation_m});
  return limits;
}

double NominalMedianResidual(double sigma) { return 1.538 * std::sqrt(2.0) * sigma; }

}  // namespace fusecal::handeye
