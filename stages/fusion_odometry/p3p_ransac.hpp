// Step 4 of the fusion odometry, first iteration (paper III-B-1: "In the first iteration, P3P RANSAC is
// used"): the camera pose of image j relative to camera i from 2D-3D correspondences, by Kneip's P3P
// (Kneip, Scaramuzza, Siegwart, "A Novel Parametrization of the Perspective-Three-Point Problem for a
// Direct Computation of Absolute Camera Position and Orientation", CVPR 2011) inside RANSAC on unit
// bearing vectors (OpenGV), so it works for pinhole and panoramic cameras alike.
//
// OpenGV's absolute pose maps the camera into the "world": p_world = R p_camera + t. Here the world is
// camera i and the camera is camera j, so its transformation is directly A = T_ci_cj.
#pragma once

#include <vector>

#include "stages/foundation/se3.hpp"
#include "stages/fusion_odometry/settings.hpp"
#include "stages/fusion_odometry/types.hpp"

namespace fusecal::fusion_odometry {

struct P3pResult {
  bool ok = false;
  Isometry3 T_ci_cj = Isometry3::Identity();
  std::vector<int> inliers;
  int iterations = 0;
};

// threshold_rad: inlier angle between v'_j and A^-1 p_ci (OpenGV scores 1 - cos of it). Deterministic
// (fixed seed). Needs at least 4 correspondences (3 for P3P, 1 to choose among its solutions).
P3pResult P3pRansac(const Correspondences& correspondences, double threshold_rad, const RansacSettings& settings);

// Correspondences whose angle between v'_j and A^-1 p_ci is within threshold_rad (in front of camera j).
std::vector<int> PoseInliers(const Correspondences& correspondences, const Isometry3& T_ci_cj, double threshold_rad);

}  // namespace fusecal::fusion_odometry
