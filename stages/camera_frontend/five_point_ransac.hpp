// 5-point RANSAC on bearing vectors (paper section III-A-1: "the essential matrix is estimated by the
// 5-point algorithm with RANSAC"), and the rotation-only RANSAC used to recognise pure rotation.
// Minimal solvers from OpenGV (Kneip and Furgale, ICRA 2014): Stewenius or Nister 5-point; bearing vectors
// make them work for any camera model.
//
// The sample-consensus loop is ours, not OpenGV's: OpenGV scores a hypothesis by triangulating every
// correspondence and counting those that reproject within the threshold in both views, and rejects every
// point that triangulates behind a camera. Under forward motion (KITTI) about half of the distant points
// triangulate behind a camera through noise alone, so the true motion lost to a sideways translation with
// a compensating rotation of several degrees. Here a hypothesis is scored by MSAC (Torr and Zisserman 2000)
// on the angle to the epipolar plane, and only points behind a camera with a parallax clearly above noise
// count against it.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "stages/camera_frontend/bearings.hpp"
#include "stages/camera_frontend/settings.hpp"

namespace fusecal::camera_frontend {

struct RansacResult {
  bool ok = false;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // R_ci_cj
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      // direction of t_ci_cj (unit; zero for rotation-only)
  std::vector<int> inliers;                         // indices into the bearing vectors
  int iterations = 0;
};

// Motions (R, t), A = T_ci_cj, whose essential matrix [t]x R satisfies f_i^T [t]x R f_j = 0 on the given
// correspondences (5 of them), one per real solution of the minimal solver: of the four motions sharing an
// essential matrix, the one with the sample in front of both cameras.
std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> FivePointMotions(const Bearings& f_i, const Bearings& f_j,
                                                                          const std::vector<int>& sample,
                                                                          const std::string& algorithm);

// Whether a correspondence fits the motion: |angle to the epipolar plane| <= threshold_rad, and not
// triangulated behind a camera unless its parallax (angle between f_i and R f_j) is below 2 threshold_rad
// (a distant point, whose depth sign noise decides).
bool IsEpipolarInlier(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Eigen::Vector3d& f_i,
                      const Eigen::Vector3d& f_j, double threshold_rad);

// Indices of all correspondences that fit the motion (IsEpipolarInlier).
std::vector<int> EpipolarInliers(const Bearings& f_i, const Bearings& f_j, const Eigen::Matrix3d& R,
                                 const Eigen::Vector3d& t, double threshold_rad);

// Relative pose A = T_ci_cj (p_i = R p_j + t) from matched bearings f_i[k] <-> f_j[k]: MSAC with the cost
// min(sin^2 e, sin^2 threshold) per correspondence, e the angle to the epipolar plane (the cap also for
// points behind a camera, see IsEpipolarInlier); adaptive number of iterations for settings.probability.
// Deterministic (fixed seed).
RansacResult FivePointRansac(const Bearings& f_i, const Bearings& f_j, const RansacSettings& settings,
                             double threshold_rad);

// Rotation-only model f_i = R f_j (OpenGV rotation-only RANSAC, Arun's method on minimal samples).
// Inlier: angle between f_i and R f_j below sqrt(2) * threshold_rad (both bearings are noisy).
RansacResult RotationOnlyRansac(const Bearings& f_i, const Bearings& f_j, const RansacSettings& settings,
                                double threshold_rad);

}  // namespace fusecal::camera_frontend
