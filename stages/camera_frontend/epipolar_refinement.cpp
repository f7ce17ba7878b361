#include "stages/camera_frontend/epipolar_refinement.hpp"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <cmath>

#include "stages/camera_frontend/covariance.hpp"

namespace fusecal::camera_frontend {

namespace {

// asin(f_i . n), n = (t x R f_j) / |t x R f_j|: the angle between f_i and the epipolar plane.
struct EpipolarAngleCost {
  EpipolarAngleCost(const Eigen::Vector3d& f_i, const Eigen::Vector3d& f_j) : f_i(f_i), f_j(f_j) {}

  template <typename T>
  bool operator()(const T* q_ptr, const T* t_ptr, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_ptr);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t(t_ptr);
    const Eigen::Matrix<T, 3, 1> n = t.cross(q * f_j.cast<T>());
    const T norm_squared = n.squaredNorm();
    if (norm_squared < T(1e-20)) {  // R f_j along t: the plane is undefined, no information
      residual[0] = T(0);
      return true;
    }
    T s = n.dot(f_i.cast<T>()) / ceres::sqrt(norm_squared);
    if (s > T(1)) s = T(1);
    if (s < T(-1)) s = T(-1);
    residual[0] = ceres::asin(s);
    return true;
  }

  Eigen::Vector3d f_i, f_j;
};

// Covariance in the tangent spaces of the two manifolds, mapped to [d_rot; d_t] of the header.
bool ComputeCovariance(ceres::Problem* problem, double* q, double* t, const Eigen::Matrix3d& R, double sigma2,
                       Matrix6* covariance) {
  Eigen::MatrixXd tangent;  // 5x5: quaternion tangent (3), sphere tangent (2)
  if (!TangentCovariance(problem, {q, t}, &tangent) || tangent.rows() != 5) return false;

  // EigenQuaternionManifold: q (+) delta = [cos|delta|, sin|delta| delta/|delta|] * q, a LEFT rotation by
  // 2 delta, i.e. R = Exp(2 delta) R_hat = R_hat Exp(2 R_hat^T delta): d_rot = 2 R^T delta.
  Eigen::Matrix<double, 6, 5> J = Eigen::Matrix<double, 6, 5>::Zero();
  J.block<3, 3>(0, 0) = 2.0 * R.transpose();
  Eigen::Matrix<double, 3, 2, Eigen::RowMajor> sphere_jacobian;
  ceres::SphereManifold<3> sphere;
  if (!sphere.PlusJacobian(t, sphere_jacobian.data())) return false;
  J.block<3, 2>(3, 3) = sphere_jacobian;
  *covariance = sigma2 * J * tangent * J.transpose();
  return covariance->allFinite();
}

}  // namespace

EpipolarRefinement RefineEpipolar(const Bearings& f_i, const Bearings& f_j, const std::vector<int>& inliers,
                                  const Eigen::Matrix3d& R0, const Eigen::Vector3d& t0, double loss_scale_rad,
                                  int max_iterations, bool compute_covariance) {
  EpipolarRefinement out;
  if (inliers.size() < 6 || !(t0.norm() > 0)) return out;
  Eigen::Quaterniond q_init(R0);
  q_init.normalize();
  double q[4] = {q_init.x(), q_init.y(), q_init.z(), q_init.w()};  // Eigen's memory order
  Eigen::Vector3d t_init = t0.normalized();
  double t[3] = {t_init.x(), t_init.y(), t_init.z()};

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::CauchyLoss loss(loss_scale_rad);
  for (int k : inliers) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<EpipolarAngleCost, 1, 4, 3>(new EpipolarAngleCost(f_i[k], f_j[k])), &loss, q,
        t);
  }
  problem.SetManifold(q, new ceres::EigenQuaternionManifold);
  problem.SetManifold(t, new ceres::SphereManifold<3>);

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = max_iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  options.function_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);

  const Eigen::Quaterniond q_final(q[3], q[0], q[1], q[2]);
  out.R = q_final.normalized().toRotationMatrix();
  out.t = Eigen::Vector3d(t[0], t[1], t[2]).normalized();
  out.ok = summary.IsSolutionUsable() && out.R.allFinite() && out.t.allFinite();
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.iterations = static_cast<int>(summary.iterations.size()) - 1;
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  if (!out.ok || !compute_covariance) return out;

  std::vector<double> abs_residuals;
  abs_residuals.reserve(inliers.size());
  for (int k : inliers) abs_residuals.push_back(std::abs(EpipolarAngle(out.R, out.t, f_i[k], f_j[k])));
  const double sigma = 1.4826 * Median(abs_residuals);
  out.covariance_ok = ComputeCovariance(&problem, q, t, out.R, sigma * sigma, &out.covariance);
  if (!out.covariance_ok) out.covariance = Matrix6::Identity();
  return out;
}

}  // namespace fusecal::camera_frontend
