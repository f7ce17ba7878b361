#include "stages/handeye/rotation_noise.hpp"

#include <algorithm>

#include "stages/handeye/pair_model.hpp"
#include "stages/handeye/translation_solver.hpp"

namespace fusecal::handeye {
namespace {

// Unit rotation axis of the LiDAR motion; nullopt for a motion too small to have one.
std::optional<Eigen::Vector3d> MotionAxis(const MotionPair& pair) {
  const Eigen::Vector3d w = LogSO3(pair.B.linear());
  if (!(w.norm() > 1e-9)) return std::nullopt;
  return Eigen::Vector3d(w.normalized());
}

// The class of a motion about the unit axis k: the frame axis it lies mostly along.
int AxisClass(const Eigen::Vector3d& k) {
  int c = 0;
  k.cwiseAbs().maxCoeff(&c);
  return c;
}

}  // namespace

Eigen::Matrix3d RotationResidualCovariance(const MotionPair& pair, const RotationNoiseByAxis& noise) {
  const auto k = MotionAxis(pair);
  if (!k) return Eigen::Matrix3d(noise.across_variance.rowwise().mean().asDiagonal());
  const Eigen::Matrix3d D = noise.across_variance.col(AxisClass(*k)).asDiagonal();
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - *k * k->transpose();
  return P * D * P + noise.axial_variance * *k * k->transpose();
}

std::optional<RotationNoiseByAxis> EstimateRotationNoiseByAxis(const std::vector<MotionPair>& pairs,
                                                               const Eigen::Matrix3d& R, double floor_variance,
                                                               double prior_components) {
  struct Used {
    Eigen::Vector3d axis, residual;
    Eigen::Matrix3d jacobian;
  };
  std::vector<Used> used;
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  for (const auto& p : pairs) {
    if (p.cov_A && p.cov_B) continue;
    const auto k = MotionAxis(p);
    if (!k) continue;
    // d r / d delta at R Exp(delta): I - R_b^T (paper Eq. (2)); its null space is the motion's axis.
    const Eigen::Matrix3d J = JacobianWrtExtrinsic(p, R).topLeftCorner<3, 3>();
    used.push_back({*k, RotationResidual(p, R), J});
    normal += J.transpose() * J;
  }
  if (used.size() < 3) return std::nullopt;
  // The fit of R absorbs part of each residual: E[r r^T] = (I - H_ii) Sigma with the hat block
  // H_ii = J_i (sum J^T J)^+ J_i^T. A component's weight is its 1 - leverage, so a motion that alone fixes a
  // direction of R (leverage 1) says nothing of the noise there.
  const Eigen::Matrix3d normal_pinv = SymmetricPseudoInverse(normal, 1e-9, nullptr);

  Eigen::Matrix3d sum_across = Eigen::Matrix3d::Zero(), weight_across = Eigen::Matrix3d::Zero();
  double sum_axial = 0.0;
  for (const auto& u : used) {
    const double along = u.axis.dot(u.residual);
    const Eigen::Vector3d across = u.residual - along * u.axis;
    const Eigen::Vector3d leverage = (u.jacobian * normal_pinv * u.jacobian.transpose()).diagonal();
    const int c = AxisClass(u.axis);
    sum_across.col(c) += across.cwiseAbs2();
    // E[across_j^2] = (1 - h_jj) sum_m P_jm^2 v_mc; with P_jj = 1 - k_j^2 as the weight of v_jc (exact for
    // axes along the frame's axes, the motions a rig makes).
    weight_across.col(c) +=
        (Eigen::Vector3d::Ones() - u.axis.cwiseAbs2()).cwiseProduct((Eigen::Vector3d::Ones() - leverage).cwiseMax(0.0));
    sum_axial += along * along;  // J k = 0: the fit leaves the angle's error alone
  }
  const double total_weight = weight_across.sum();
  if (!(total_weight > 0.0)) return std::nullopt;
  const double pooled = sum_across.sum() / total_weight;
  RotationNoiseByAxis out;
  out.R_camera_lidar = R;
  for (int c = 0; c < 3; ++c)
    for (int j = 0; j < 3; ++j) {
      const double weight = prior_components + weight_across(j, c);
      out.across_variance(j, c) = weight > 0.0 ? (prior_components * pooled + sum_across(j, c)) / weight : pooled;
    }
  out.axial_variance = sum_axial / static_cast<double>(used.size());
  out.across_variance = out.across_variance.cwiseMax(floor_variance);
  out.axial_variance = std::max(out.axial_variance, floor_variance);
  return out;
}

}  // namespace fusecal::handeye
