#include "stages/camera_frontend/rotation_only.hpp"

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <cmath>

#include "stages/camera_frontend/covariance.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal::camera_frontend {

namespace {

struct RotationChordCost {
  RotationChordCost(const Eigen::Vector3d& f_i, const Eigen::Vector3d& f_j) : f_i(f_i), f_j(f_j) {}
  template <typename T>
  bool operator()(const T* q_ptr, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_ptr);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = f_i.cast<T>() - q * f_j.cast<T>();
    return true;
  }
  Eigen::Vector3d f_i, f_j;
};

}  // namespace

RotationOnlyFit FitRotationOnly(const Bearings& f_i, const Bearings& f_j, const std::vector<int>& indices,
                                double loss_scale_rad, int max_iterations, bool compute_covariance) {
  RotationOnlyFit out;
  if (indices.size() < 3) return out;
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (int k : indices) M += f_i[k] * f_j[k].transpose();
  Eigen::Quaterniond q_init(NearestRotation(M));
  double q[4] = {q_init.x(), q_init.y(), q_init.z(), q_init.w()};

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::CauchyLoss loss(loss_scale_rad);
  for (int k : indices) {
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<RotationChordCost, 3, 4>(new RotationChordCost(f_i[k], f_j[k])), &loss, q);
  }
  problem.SetManifold(q, new ceres::EigenQuaternionManifold);
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = max_iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.function_tolerance = 1e-12;
  options.parameter_tolerance = 1e-12;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);

  out.R = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
  out.ok = summary.IsSolutionUsable() && out.R.allFinite();
  if (!out.ok) return out;
  std::vector<double> residuals;
  residuals.reserve(indices.size());
  for (int k : indices) residuals.push_back(RotationOnlyAngle(out.R, f_i[k], f_j[k]));
  out.median_residual_rad = Median(residuals);
  if (!compute_covariance) return out;

  Eigen::MatrixXd tangent;
  if (TangentCovariance(&problem, {q}, &tangent) && tangent.rows() == 3) {
    // The angle residual is 2D (3 chord components, one along f_i is second order): its median is about
    // 1.18 sigma per axis for Gaussian noise (Rayleigh), so sigma = median / 1.1774.
    const double sigma = out.median_residual_rad / 1.1774;
    const Eigen::Matrix3d J = 2.0 * out.R.transpose();  // see epipolar_refinement.cpp: d_rot = 2 R^T delta
    out.covariance = sigma * sigma * J * tangent * J.transpose();
    out.covariance_ok = out.covariance.allFinite();
  }
  if (!out.covariance_ok) out.covariance = Eigen::Matrix3d::Identity();
  return out;
}

}  // namespace fusecal::camera_frontend
