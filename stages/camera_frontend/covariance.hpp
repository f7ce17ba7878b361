// Covariance of a Ceres least-squares problem at its solution, computed from the Jacobian directly (no
// ceres::Covariance, which logs an error for every rank-deficient problem, e.g. a pair of identical images).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace ceres {
class Problem;
}

namespace fusecal::camera_frontend {

// (J^T J)^-1 with J the Jacobian of the (robustified) residuals with respect to the tangent spaces of the
// given parameter blocks, in this order (Ceres' Problem::Evaluate applies the manifolds). It assumes unit
// residual variance: scale it by the residual variance. False when J^T J is rank deficient (reciprocal
// condition number below 1e-12) or not finite.
bool TangentCovariance(ceres::Problem* problem, const std::vector<double*>& blocks, Eigen::MatrixXd* covariance);

}  // namespace fusecal::camera_frontend
