// Covariance of the registration from the Gauss-Newton Hessian at the solution (as small_gicp and the
// hand-eye weighting downstream expect): Cov = sigma^2 H^-1, sigma^2 = sum w r^2 / (sum w - 6), order
// [rotation (rad); translation (m)] of the right perturbation T * Exp(d).
#pragma once

#include "stages/foundation/se3.hpp"
#include "stages/lidar_icp/icp.hpp"

namespace fusecal::lidar_icp {

// False (cov untouched) when H is not positive definite: the geometry does not constrain all 6 DoF.
bool CovarianceFromHessian(const Linearization& lin, Matrix6* cov);

// Conditioning of the Hessian, lambda_min / lambda_max, with rotation scaled by `length_m` (the RMS range
// of the points) so both blocks are in metres. Near 0 when a direction is unconstrained: a single plane
// leaves yaw and horizontal translation free, a corridor its axis. Noise keeps H invertible there, so
// this, not invertibility, detects degenerate geometry.
double Conditioning(const Linearization& lin, double length_m);

// Largest standard deviations of the rotation (rad) and translation (m) blocks.
void CovarianceExtent(const Matrix6& cov, double* rotation_std_rad, double* translation_std_m);

}  // namespace fusecal::lidar_icp
