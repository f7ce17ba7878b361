#include "stages/fusion_odometry/pose_refinement.hpp"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>

namespace fusecal::fusion_odometry {

namespace {

// r = v'_j x Proj(R_a^T (p_ci - t_a)), A = (R_a, t_a) = T_ci_cj; |r| = sin of the angle (paper III-B-1).
struct BearingError {
  BearingError(const Eigen::Vector3d& p_ci, const Eigen::Vector3d& v_j) : p_ci(p_ci), v_j(v_j) {}

  template <typename T>
  bool operator()(const T* q_ci_cj, const T* t_ci_cj, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_ci_cj);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(t_ci_cj);
    const Eigen::Matrix<T, 3, 1> p_cj = q.conjugate() * (p_ci.cast<T>() - t);
    const Eigen::Matrix<T, 3, 1> r = v_j.cast<T>().cross(p_cj / p_cj.norm());
    residual[0] = r[0];
    residual[1] = r[1];
    residual[2] = r[2];
    return true;
  }

  Eigen::Vector3d p_ci, v_j;
};

// The same residual as a function of the perturbation d = [d_rot; d_t] of A: R = R_hat Exp(d_rot),
// t = t_hat + d_t, so p_cj = Exp(-d_rot) R_hat^T (p_ci - t_hat - d_t). Evaluated at d = 0 for the Jacobian.
struct PerturbedBearingError {
  PerturbedBearingError(const Isometry3& T_hat, const Eigen::Vector3d& p_ci, const Eigen::Vector3d& v_j)
      : R_hat_T(T_hat.linear().transpose()), t_hat(T_hat.translation()), p_ci(p_ci), v_j(v_j) {}

  template <typename T>
  bool operator()(const T* d, T* residual) const {
    const Eigen::Matrix<T, 3, 1> dt(d[3], d[4], d[5]);
    const Eigen::Matrix<T, 3, 1> q = R_hat_T.cast<T>() * (p_ci.cast<T>() - t_hat.cast<T>() - dt);
    const T minus_rot[3] = {-d[0], -d[1], -d[2]};
    Eigen::Matrix<T, 3, 1> p_cj;
    ceres::AngleAxisRotatePoint(minus_rot, q.data(), p_cj.data());
    const Eigen::Matrix<T, 3, 1> r = v_j.cast<T>().cross(p_cj / p_cj.norm());
    residual[0] = r[0];
    residual[1] = r[1];
    residual[2] = r[2];
    return true;
  }

  Eigen::Matrix3d R_hat_T;
  Eigen::Vector3d t_hat, p_ci, v_j;
};

ceres::LossFunction* MakeLoss(const RefinementSettings& settings, double scale_rad) {
  // The residual is sin(angle) ~ angle; the losses act on its squared norm.
  if (settings.loss == "cauchy") return new ceres::CauchyLoss(scale_rad);
  if (settings.loss == "huber") return new ceres::HuberLoss(scale_rad);
  return nullptr;
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  return v[mid];
}

// One robust solve over the given correspondences. Returns false when Ceres reports no usable solution.
bool Solve(const Correspondences& correspondences, const std::vector<int>& use, double loss_scale_rad,
           const RefinementSettings& settings, Isometry3* T_ci_cj, int* iterations) {
  Eigen::Quaterniond q(T_ci_cj->linear());
  q.normalize();
  double q_data[4] = {q.x(), q.y(), q.z(), q.w()};  // Eigen's storage order, as EigenQuaternionManifold
  Eigen::Vector3d t = T_ci_cj->translation();

  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  for (int k : use) {
    const Correspondence& c = correspondences[k];
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<BearingError, 3, 4, 3>(new BearingError(c.p_ci, c.bearing_j)),
        MakeLoss(settings, loss_scale_rad), q_data, t.data());
  }
  problem.SetManifold(q_data, new ceres::EigenQuaternionManifold);

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = settings.max_iterations;
  options.function_tolerance = 1e-12;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-12;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  *iterations += static_cast<int>(summary.iterations.size());
  if (!summary.IsSolutionUsable()) return false;

  const Eigen::Quaterniond q_out(q_data[3], q_data[0], q_data[1], q_data[2]);
  if (!q_out.coeffs().allFinite() || !t.allFinite()) return false;
  *T_ci_cj = MakeIsometry(q_out.normalized().toRotationMatrix(), t);
  return true;
}

}  // namespace

bool PoseCovariance(const Correspondences& correspondences, const std::vector<int>& inliers, const Isometry3& T_ci_cj,
                    Matrix6* covariance) {
  const int n = static_cast<int>(inliers.size());
  if (n < 4) return false;
  Matrix6 H = Matrix6::Zero();
  double sum_r2 = 0.0;
  const double zero[6] = {0, 0, 0, 0, 0, 0};
  const double* parameters[1] = {zero};
  for (int k : inliers) {
    const Correspondence& c = correspondences[k];
    ceres::AutoDiffCostFunction<PerturbedBearingError, 3, 6> cost(
        new PerturbedBearingError(T_ci_cj, c.p_ci, c.bearing_j));
    Eigen::Vector3d r;
    Eigen::Matrix<double, 3, 6, Eigen::RowMajor> J;
    double* jacobians[1] = {J.data()};
    if (!cost.Evaluate(parameters, r.data(), jacobians)) return false;
    H += J.transpose() * J;
    sum_r2 += r.squaredNorm();
  }
  const Eigen::SelfAdjointEigenSolver<Matrix6> eigen(H);
  const double largest = eigen.eigenvalues().maxCoeff();
  if (!(largest > 0) || !(eigen.eigenvalues().minCoeff() > 1e-12 * largest)) return false;
  const double sigma2 = sum_r2 / std::max(1, 2 * n - 6);  // |r|^2 holds two independent components
  *covariance = sigma2 * eigen.eigenvectors() * eigen.eigenvalues().cwiseInverse().asDiagonal() *
                eigen.eigenvectors().transpose();
  return covariance->allFinite();
}

RefinementResult RefinePose(const Correspondences& correspondences, const Isometry3& initial_T_ci_cj,
                            const std::vector<int>& initial_inliers, double pixel_angle_rad,
                            const RefinementSettings& settings) {
  RefinementResult out;
  out.T_ci_cj = initial_T_ci_cj;
  const double loss_scale_rad = settings.loss_scale_px * pixel_angle_rad;
  const double max_residual_rad = settings.max_residual_px * pixel_angle_rad;
  std::vector<int> use = initial_inliers;
  std::vector<double> angles(correspondences.size());
  for (int round = 0; round < settings.rounds; ++round) {
    if (use.size() < 4) {
      out.message = "too few correspondences to refine (" + std::to_string(use.size()) + ")";
      return out;
    }
    if (!Solve(correspondences, use, loss_scale_rad, settings, &out.T_ci_cj, &out.iterations)) {
      out.message = "the nonlinear refinement found no usable solution";
      return out;
    }
    // Re-classify every track by its residual under the refined pose.
    const Isometry3 T_cj_ci = out.T_ci_cj.inverse();
    std::vector<int> inliers;
    for (size_t k = 0; k < correspondences.size(); ++k) {
      const Correspondence& c = correspondences[k];
      const Eigen::Vector3d p_cj = T_cj_ci * c.p_ci;
      angles[k] = BearingAngle(c.bearing_j, p_cj);
      if (angles[k] <= max_residual_rad) inliers.push_back(static_cast<int>(k));
    }
    const bool unchanged = inliers == use;
    use = std::move(inliers);
    if (unchanged) break;
  }
  out.inliers = use;
  if (out.inliers.size() < 4) {
    out.message = "too few inliers after refinement (" + std::to_string(out.inliers.size()) + ")";
    return out;
  }
  std::vector<double> inlier_angles;
  double sum2 = 0.0;
  for (int k : out.inliers) {
    inlier_angles.push_back(angles[k]);
    sum2 += angles[k] * angles[k];
  }
  out.rms_rad = std::sqrt(sum2 / out.inliers.size());
  out.median_rad = Median(inlier_angles);
  if (settings.compute_covariance)
    out.covariance_valid = PoseCovariance(correspondences, out.inliers, out.T_ci_cj, &out.covariance);
  out.ok = true;
  return out;
}

}  // namespace fusecal::fusion_odometry
