#include "stages/handeye/translation_solver.hpp"

#include <Eigen/Eigenvalues>

#include "stages/handeye/pair_model.hpp"

namespace fusecal::handeye {

Eigen::Matrix3d SymmetricPseudoInverse(const Eigen::Matrix3d& N, double rel_tol,
                                       std::vector<Eigen::Vector3d>* null_directions) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (N + N.transpose()));
  const double max_ev = eig.eigenvalues().cwiseAbs().maxCoeff();
  Eigen::Matrix3d Ninv = Eigen::Matrix3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d v = eig.eigenvectors().col(k);
    if (max_ev > 0.0 && eig.eigenvalues()(k) > rel_tol * max_ev) {
      Ninv += v * v.transpose() / eig.eigenvalues()(k);
    } else if (null_directions) {
      null_directions->push_back(v);
    }
  }
  return Ninv;
}

LinearTranslation SolveTranslation(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R, bool with_scales,
                                   const Eigen::Vector3d* t_prior,
                                   const std::vector<Eigen::Vector3d>& fixed_directions) {
  LinearTranslation out;
  const size_t n = pairs.size();
  std::vector<Eigen::Matrix3d> P(n, Eigen::Matrix3d::Identity());
  std::vector<Eigen::Vector3d> u(n, Eigen::Vector3d::Zero());
  std::vector<double> ta_norm(n, 0.0);
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  Eigen::Matrix3d dB = Eigen::Matrix3d::Zero();  // d b / d rotation perturbation
  int equations = 0;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Matrix3d A = pairs[i].A.linear() - Eigen::Matrix3d::Identity();
    const Eigen::Vector3d ta = pairs[i].A.translation();
    const Eigen::Vector3d tb = pairs[i].B.translation();
    ta_norm[i] = ta.norm();
    equations += 3;
    if (with_scales && ta_norm[i] > 1e-12) {
      u[i] = ta / ta_norm[i];
      P[i] -= u[i] * u[i].transpose();
      equations -= 1;  // one equation is used by s_i
    }
    const Eigen::Matrix3d AtP = A.transpose() * P[i];
    out.N += AtP * A;
    // Right-hand side: R t_b (scaleless, the s_i t_a term is projected out) or R t_b - t_a (scaled).
    b += AtP * (with_scales ? Eigen::Vector3d(R * tb) : Eigen::Vector3d(R * tb - ta));
    dB += AtP * (-R * Skew(tb));  // d(R Exp(d) t_b)/d d = -R [t_b]x
  }
  // Remove the fixed directions from the problem: they become null directions of the projected system.
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  for (const auto& d : fixed_directions) F -= d.normalized() * d.normalized().transpose();
  if (!fixed_directions.empty()) {
    out.N = F * out.N * F;
    b = F * b;
    dB = F * dB;
  }
  out.N_pinv = SymmetricPseudoInverse(out.N, 1e-12, &out.null_directions);
  out.t = out.N_pinv * b;
  if (t_prior)
    for (const auto& v : out.null_directions) out.t += v * v.dot(*t_prior);
  out.dt_drot = out.N_pinv * dB;
  out.dof = equations - 3;

  out.scales.assign(n, 1.0);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Matrix3d A = pairs[i].A.linear() - Eigen::Matrix3d::Identity();
    const Eigen::Vector3d rhs = R * pairs[i].B.translation() - A * out.t;
    if (with_scales) out.scales[i] = ta_norm[i] > 1e-12 ? u[i].dot(rhs) / ta_norm[i] : 0.0;
    const Eigen::Vector3d r = TranslationResidual(pairs[i], R, out.t, out.scales[i]);
    out.residuals.push_back(r);
    out.residual_sum_squares += r.squaredNorm();
  }
  return out;
}

}  // namespace fusecal::handeye
