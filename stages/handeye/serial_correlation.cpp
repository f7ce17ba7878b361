#include "stages/handeye/serial_correlation.hpp"

#include <cmath>

namespace fusecal::handeye {
namespace {

// kappa of a series of vectors: 1 + 2 sum of the leading lag autocorrelations that are positive beyond
// noise, normalised by the energy of all (the usual biased estimator: it damps the long lags).
double Kappa(const std::vector<Eigen::Vector3d>& series) {
  const int n = static_cast<int>(series.size());
  double energy = 0.0;
  for (const auto& v : series) energy += v.squaredNorm();
  if (n < 4 || !(energy > 0.0) || !std::isfinite(energy)) return 1.0;
  double kappa = 1.0;
  for (int lag = 1; lag <= n / 2; ++lag) {
    double sum = 0.0;
    for (int i = lag; i < n; ++i) sum += series[i].dot(series[i - lag]);
    const double rho = sum / energy;
    if (!(rho > 2.0 / std::sqrt(3.0 * (n - lag)))) break;
    kappa += 2.0 * rho;
  }
  return kappa;
}

}  // namespace

Matrix6 VarianceFactor::Inflate(const Matrix6& C) const {
  Vector6 d;
  d << Eigen::Vector3d::Constant(std::sqrt(rotation)), Eigen::Vector3d::Constant(std::sqrt(translation));
  return d.asDiagonal() * C * d.asDiagonal();
}

VarianceFactor SerialCorrelationInflation(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R,
                                          const Eigen::Vector3d& t, const NoiseModel& noise, bool scaled) {
  const int dim = scaled ? 6 : 3;
  std::vector<Eigen::VectorXd> pulls;
  pulls.reserve(pairs.size());
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(dim, dim);
  for (const auto& p : pairs) {
    const Eigen::MatrixXd W = WhiteningMatrix(ResidualCovariance(p, R, t, noise).topLeftCorner(dim, dim));
    const Eigen::MatrixXd J = W * JacobianWrtExtrinsic(p, R).topLeftCorner(dim, dim);
    pulls.push_back(J.transpose() * (W * PairResidual(p, R, t).head(dim)));
    H += J.transpose() * J;
  }
  const Eigen::MatrixXd C = PseudoInverse(H);
  const auto shares = [&](int block) {
    const Eigen::Matrix3d whiten = PseudoInverse(C.block<3, 3>(3 * block, 3 * block), nullptr, true);
    std::vector<Eigen::Vector3d> out;
    for (const auto& g : pulls) out.push_back(whiten * (C * g).segment<3>(3 * block));
    return out;
  };
  VarianceFactor f;
  f.rotation = Kappa(shares(0));
  f.translation = scaled ? Kappa(shares(1)) : f.rotation;
  return f;
}

}  // namespace fusecal::handeye
