#include "stages/lidar_icp/icp.hpp"

#include <Eigen/Cholesky>
#include <cmath>

namespace fusecal::lidar_icp {

Linearization Linearize(const PreparedCloud& target, const std::vector<Eigen::Vector3f>& source, const Isometry3& T,
                        double threshold_m, const IcpOptions& options) {
  const int threads = options.threads;
  const float tangential_sq = static_cast<float>(options.tangential_limit_m * options.tangential_limit_m);
  constexpr float kTangentialPerRangeSq = 0.015f * 0.015f;
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  const Eigen::Matrix3d Rd = T.linear();
  const float max_sq = static_cast<float>(threshold_m * threshold_m);
  // Geman-McClure scale: a third of the threshold, so residuals near the threshold weigh little.
  const double c2 = std::pow(threshold_m / 3.0, 2);
  const int n = static_cast<int>(source.size());
  Linearization total;
#pragma omp parallel num_threads(threads)
  {
    Linearization local;
#pragma omp for schedule(static) nowait
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3f q = R * source[i] + t;
      uint32_t j;
      float d2;
      if (!target.tree->Nearest(q, &j, &d2) || d2 > max_sq || !target.planar[j]) continue;
      const Eigen::Vector3f offset = q - target.points[j];
      const float r_f = target.normals[j].dot(offset);
      if (tangential_sq > 0 && d2 - r_f * r_f > std::max(tangential_sq, kTangentialPerRangeSq * q.squaredNorm()))
        continue;
      const Eigen::Vector3d nrm = target.normals[j].cast<double>();
      const double r = nrm.dot(offset.cast<double>());
      const Eigen::Vector3d nl = Rd.transpose() * nrm;  // normal in the source frame
      const Eigen::Vector3d p = source[i].cast<double>();
      Vector6 J;
      J << p.cross(nl), nl;
      const double w = 1.0 / std::pow(1.0 + r * r / c2, 2);
      local.H.noalias() += w * J * J.transpose();
      local.b.noalias() += w * r * J;
      local.weighted_sq += w * r * r;
      local.weight_sum += w;
      local.sq_sum += r * r;
      ++local.inliers;
    }
#pragma omp critical
    {
      total.H += local.H;
      total.b += local.b;
      total.weighted_sq += local.weighted_sq;
      total.weight_sum += local.weight_sum;
      total.sq_sum += local.sq_sum;
      total.inliers += local.inliers;
    }
  }
  return total;
}

LevelResult IcpLevel(const PreparedCloud& target, const std::vector<Eigen::Vector3f>& source, double threshold_m,
                     const IcpOptions& options, Isometry3* T) {
  LevelResult out;
  while (out.iterations < options.max_iterations) {
    ++out.iterations;
    const Linearization lin = Linearize(target, source, *T, threshold_m, options);
    if (lin.inliers < 6) break;
    const Vector6 d = -lin.H.ldlt().solve(lin.b);
    if (!d.allFinite()) break;
    // T <- T * Exp(d) (first-order translation part; the next iteration corrects the rest).
    T->translation() += T->linear() * d.tail<3>();
    T->linear() = NearestRotation(T->linear() * ExpSO3(d.head<3>()));
    if (d.head<3>().norm() < options.convergence_rotation_rad &&
        d.tail<3>().norm() < options.convergence_translation_m) {
      out.converged = true;
      break;
    }
  }
  return out;
}

std::vector<double> ThresholdSchedule(double first_m, double last_m, double shrink) {
  std::vector<double> out;
  for (double d = first_m; d > last_m * 1.0001 && out.size() < 32; d *= shrink) out.push_back(d);
  out.push_back(last_m);
  return out;
}

double Fitness(const PreparedCloud& target, const std::vector<Eigen::Vector3f>& source, const Isometry3& T,
               double threshold_m, int threads) {
  if (source.empty()) return 0.0;
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  const float max_sq = static_cast<float>(threshold_m * threshold_m);
  const int n = static_cast<int>(source.size());
  long hits = 0;
#pragma omp parallel for num_threads(threads) reduction(+ : hits) schedule(static)
  for (int i = 0; i < n; ++i) {
    uint32_t j;
    float d2;
    if (target.tree->Nearest(R * source[i] + t, &j, &d2) && d2 <= max_sq) ++hits;
  }
  return double(hits) / double(n);
}

}  // namespace fusecal::lidar_icp
