#include "stages/fusion_odometry/p3p_ransac.hpp"

#include <cmath>
#include <memory>
#include <opengv/absolute_pose/CentralAbsoluteAdapter.hpp>
#include <opengv/sac/Ransac.hpp>
#include <opengv/sac_problems/absolute_pose/AbsolutePoseSacProblem.hpp>

namespace fusecal::fusion_odometry {

P3pResult P3pRansac(const Correspondences& correspondences, double threshold_rad, const RansacSettings& settings) {
  using Problem = opengv::sac_problems::absolute_pose::AbsolutePoseSacProblem;
  P3pResult out;
  if (correspondences.size() < 4) return out;
  opengv::bearingVectors_t bearings;
  opengv::points_t points;
  bearings.reserve(correspondences.size());
  points.reserve(correspondences.size());
  for (const Correspondence& c : correspondences) {
    bearings.push_back(c.bearing_j);
    points.push_back(c.p_ci);
  }
  opengv::absolute_pose::CentralAbsoluteAdapter adapter(bearings, points);
  opengv::sac::Ransac<Problem> ransac;
  ransac.sac_model_ = std::make_shared<Problem>(adapter, Problem::KNEIP, /*randomSeed=*/false);
  ransac.threshold_ = 1.0 - std::cos(threshold_rad);
  ransac.max_iterations_ = settings.max_iterations;
  ransac.probability_ = settings.probability;
  if (!ransac.computeModel(0)) return out;
  const opengv::transformation_t& T = ransac.model_coefficients_;
  if (!T.allFinite()) return out;
  out.T_ci_cj = MakeIsometry(NearestRotation(T.leftCols<3>()), T.col(3));
  out.iterations = ransac.iterations_;
  // Re-classify with our own test (angle and chirality) so that every step counts inliers alike.
  out.inliers = PoseInliers(correspondences, out.T_ci_cj, threshold_rad);
  out.ok = out.inliers.size() >= 4;
  return out;
}

std::vector<int> PoseInliers(const Correspondences& correspondences, const Isometry3& T_ci_cj, double threshold_rad) {
  const Isometry3 T_cj_ci = T_ci_cj.inverse();
  const double cos_threshold = std::cos(threshold_rad);
  std::vector<int> inliers;
  for (size_t k = 0; k < correspondences.size(); ++k) {
    const Correspondence& c = correspondences[k];
    const Eigen::Vector3d p_cj = T_cj_ci * c.p_ci;
    const double norm = p_cj.norm();
    if (norm > 0 && c.bearing_j.dot(p_cj) >= cos_threshold * norm) inliers.push_back(static_cast<int>(k));
  }
  return inliers;
}

}  // namespace fusecal::fusion_odometry
