// Motion pairs that share motion count as fewer pairs. Pairs taken over overlapping windows of one
// trajectory (stations k..k+w for every k, or pairs derived from chained odometry), or consecutive motions
// of one bundle adjustment or structure-from-motion trajectory, carry correlated errors: a solve that
// treats them as independent reports a standard deviation too small by about the square root of the
// overlap. What the estimate feels of that correlation is the correlation of each pair's share of the
// estimate's error, H^-1 g_i, with g_i = J_i^T W_i^T W_i r_i its pull on the extrinsic (J_i the pair's
// Jacobian with respect to the extrinsic, W_i its whitening, r_i its residual) and H = sum_i J_i^T W_i^T
// W_i J_i. Per block (rotation, translation), whitened by that block of H^-1 and in the order of the pairs,
// the lag-l autocorrelation rho_l of the shares gives the variance inflation kappa = 1 + 2 sum_l rho_l (the
// effective-sample-size correction of a correlated series), summed over the leading lags that are positive
// beyond noise (2 / sqrt(terms)), never below 1. Correlated residuals alone do not inflate: a handheld rig
// that turns back and forth pulls the rotation one way and then the other with the same error, and the
// errors cancel; but its translations, all along the way it walks, pull alike, and the rotation the scaled
// solve takes from them inflates.
// Independent pairs (consecutive stops, each motion measured once) give kappa = 1 up to chance.
#pragma once

#include <vector>

#include "stages/handeye/handeye_types.hpp"
#include "stages/handeye/pair_model.hpp"

namespace fusecal::handeye {

// The variance inflation of the rotation and of the translation of the estimate.
struct VarianceFactor {
  double rotation = 1.0;
  double translation = 1.0;
  double Largest() const { return rotation > translation ? rotation : translation; }
  VarianceFactor operator*(double f) const { return {rotation * f, translation * f}; }
  // D C D with D = diag(sqrt(rotation) I, sqrt(translation) I): stays positive semi-definite.
  Matrix6 Inflate(const Matrix6& C) const;
};

// kappa for the pairs at (R, t) under `noise`; `scaled`: the whole extrinsic, otherwise the rotation only
// (a scaleless camera translation has its own unknown scale), whose kappa then stands for both.
VarianceFactor SerialCorrelationInflation(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R,
                                          const Eigen::Vector3d& t, const NoiseModel& noise, bool scaled);

}  // namespace fusecal::handeye
