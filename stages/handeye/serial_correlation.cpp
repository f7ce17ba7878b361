#include "handeye/serial_correlation.hpp"

#include <Eigen/Cholesky>
#include <cmath>

namespace fusecal::handeye {

double SerialCorrelationInflation(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R,
                                  const Eigen::Vector3d& t, const NoiseModel& noise, bool scaled) {
  const int n = static_cast<int>(pairs.size());
  const int dim = scaled ? 6 : 3;
  std::vector<Eigen::VectorXd> whitened;
  whitened.reserve(n);
  for (const auto& p : pairs) {
    const Eigen::MatrixXd W = WhiteningMatrix(ResidualCovariance(p, R, t, noise).topLeftCorner(dim, dim));
    whitened.push_back(W * PairResidual(p, R, t).head(dim));
  }
  double energy = 0.0;
  for (const auto& v : whitened) energy += v.squaredNorm();
  if (n < 4 || !(energy > 0.0) || !std::isfinite(energy)) return 1.0;
  double kappa = 1.0;
  for (int lag = 1; lag <= n / 2; ++lag) {
    double sum = 0.0;
    for (int i = lag; i < n; ++i) sum += whitened[i].dot(whitened[i - lag]);
    // Normalised by the energy of all pairs (the usual biased estimator: it damps the long lags).
    const double rho = sum / energy;
    const double terms = static_cast<double>(dim) * (n - lag);
    if (!(rho > 2.0 / std::sqrt(terms))) break;
    kappa += 2.0 * rho;
  }
  return kappa;
}

}  // namespace fusecal::handeye
