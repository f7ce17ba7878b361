// Motion pairs that share motion count as fewer pairs. Pairs taken over overlapping windows of one
// trajectory (stations k..k+w for every k, or pairs derived from chained odometry) carry the same noise
// several times: their residuals are correlated in sequence, and a solve that treats them as independent
// reports a standard deviation too small by about the square root of the overlap. The residuals say so:
// the lag-l autocorrelation rho_l of the whitened residual vectors, in the order of the pairs, gives the
// variance inflation kappa = 1 + 2 sum_l rho_l (the effective-sample-size correction of a correlated
// series), summed over the leading lags that are positive beyond noise (2 / sqrt(terms)), never below 1.
// Independent pairs (consecutive stops, each motion measured once) give kappa = 1 up to chance.
#pragma once

#include <vector>

#include "handeye/handeye_types.hpp"
#include "handeye/pair_model.hpp"

namespace fusecal::handeye {

// kappa for the pairs at (R, t) under `noise`; `scaled`: whiten all six residual components, otherwise
// the rotation only (a scaleless camera translation has its own unknown scale).
double SerialCorrelationInflation(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R,
                                  const Eigen::Vector3d& t, const NoiseModel& noise, bool scaled);

}  // namespace fusecal::handeye
