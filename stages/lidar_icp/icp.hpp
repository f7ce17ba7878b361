// Point-to-plane ICP, Gauss-Newton on SE(3) with a Geman-McClure kernel (KISS-ICP / small_gicp style),
// with the schedule of the paper (III-A-1): the correspondence distance threshold starts large and shrinks
// level by level; correspondences beyond it are rejected as outliers.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "stages/foundation/se3.hpp"
#include "stages/lidar_icp/preprocess.hpp"

namespace fusecal::lidar_icp {

struct IcpOptions {
  double convergence_rotation_rad = 1e-6;
  double convergence_translation_m = 1e-5;
  int max_iterations = 15;  // per level
  // Correspondences whose offset along the target plane exceeds max(tangential_limit_m, 1.5 % of the
  // range) are rejected: they are source points beyond the edge of the target's surface (partial
  // overlap, the band of a multi-beam LiDAR), where the noise of the target normal, multiplied by the
  // consistent outward offset, biases the solution. 0 = no limit.
  double tangential_limit_m = 0.0;
  int threads = 1;
};

// Normal equations at one pose. Perturbation on the right, T * Exp(d), d = [omega; nu]; residual
// r = n^T (R p + t - m) of source point p against its nearest planar target point m with normal n.
struct Linearization {
  Matrix6 H = Matrix6::Zero();  // sum w J J^T
  Vector6 b = Vector6::Zero();  // sum w J r
  double weighted_sq = 0.0;     // sum w r^2
  double weight_sum = 0.0;
  double sq_sum = 0.0;  // sum r^2 over inliers (unweighted)
  size_t inliers = 0;   // source points with a planar target point within the threshold
};

Linearization Linearize(const PreparedCloud& target, const std::vector<Eigen::Vector3f>& source,
                        const Isometry3& T_target_source, double threshold_m, const IcpOptions& options);

struct LevelResult {
  int iterations = 0;
  bool converged = false;  // the last update was below the tolerance
};

// Gauss-Newton iterations at one threshold until the update is below the tolerance.
LevelResult IcpLevel(const PreparedCloud& target, const std::vector<Eigen::Vector3f>& source, double threshold_m,
                     const IcpOptions& options, Isometry3* T_target_source);

// Thresholds of the schedule: first, first*shrink, ... while above last, then last.
std::vector<double> ThresholdSchedule(double first_m, double last_m, double shrink);

// Share of source points whose nearest target point (any, planar or not) is within threshold_m.
double Fitness(const PreparedCloud& target, const std::vector<Eigen::Vector3f>& source,
               const Isometry3& T_target_source, double threshold_m, int threads);

}  // namespace fusecal::lidar_icp
