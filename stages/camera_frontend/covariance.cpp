#include "stages/camera_frontend/covariance.hpp"

#include <ceres/ceres.h>

#include <Eigen/Eigenvalues>

namespace fusecal::camera_frontend {

bool TangentCovariance(ceres::Problem* problem, const std::vector<double*>& blocks, Eigen::MatrixXd* covariance) {
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = blocks;
  options.apply_loss_function = true;
  options.num_threads = 1;
  ceres::CRSMatrix crs;
  if (!problem->Evaluate(options, nullptr, nullptr, nullptr, &crs)) return false;
  Eigen::MatrixXd information = Eigen::MatrixXd::Zero(crs.num_cols, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {  // accumulate J^T J row by row
    for (int a = crs.rows[row]; a < crs.rows[row + 1]; ++a)
      for (int b = crs.rows[row]; b < crs.rows[row + 1]; ++b)
        information(crs.cols[a], crs.cols[b]) += crs.values[a] * crs.values[b];
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(information);
  if (eig.info() != Eigen::Success || crs.num_cols == 0) return false;
  const Eigen::VectorXd values = eig.eigenvalues();
  if (!(values.minCoeff() > 1e-12 * values.maxCoeff())) return false;
  *covariance = eig.eigenvectors() * values.cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
  return covariance->allFinite();
}

}  // namespace fusecal::camera_frontend
