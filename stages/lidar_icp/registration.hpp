// LiDAR motion B_i = T_li_lj between two station scans, with no initial guess (Ishikawa et al., IROS 2018,
// section III-A-1: "ICP ... starting from a large correspondence distance threshold that shrinks while
// outliers are rejected"). Pipeline (registration.cpp):
//   1. preprocess both scans: drop non-finite points, crop range, voxel downsample (each voxel the
//      centroid of its 3 x 3 x 3 neighbourhood, unbiased by the grid: preprocess.hpp), target normals;
//   2. global alignment: the rig is turned between stations (any yaw, tilt up to ~45 deg, ~1 m
//      translation), so rotations are searched on a grid scored against a truncated distance field of
//      the target that also knows the target's free space, and the best candidates are hill-climbed in
//      6 DoF (global_alignment.cpp, distance_field.cpp);
//   3. coarse-to-fine point-to-plane ICP with a robust kernel and a shrinking correspondence threshold,
//      run from the best candidates, the best one carried to the fine level (icp.cpp);
//   4. acceptance: inlier ratio, free-space consistency (consistency.cpp), conditioning; covariance from
//      the Hessian (covariance.cpp).
// No LCM, no file I/O, no PCL. Never throws on bad input: a failed registration is not usable() and says
// why in failure_reason.
#pragma once

#include <string>

#include "stages/foundation/point_cloud.hpp"
#include "stages/foundation/se3.hpp"
#include "stages/foundation/stage_result.hpp"

namespace fusecal::lidar_icp {

struct RegistrationSettings {
  // --- preprocessing ---
  double min_range_m = 1.0;  // closer points (the rig itself, the operator) are dropped
  double max_range_m = 100.0;
  // Voxel size of the fine level; 0 = automatic from the scene scale (1.2 % of the median range,
  // clamped to [0.05, 0.25] m), so rooms and streets both work.
  double voxel_size_m = 0.0;
  int max_source_points = 15000;  // the fine source cloud is subsampled evenly to at most this many
  int normal_neighbors = 20;      // k of the k-NN plane fit of the target normals
  int min_points = 100;           // fewer valid points after preprocessing: failure

  // --- global alignment (no initial guess) ---
  bool global_alignment = true;     // false: ICP from the guess alone (identity unless given)
  double max_tilt_deg = 60.0;       // tilt of scan j's z axis in frame i searched; 180 = all of SO(3)
  double rotation_step_deg = 10.0;  // grid step of the rotation search
  int global_candidates = 6;        // candidates hill-climbed and tried by the coarse ICP
  int global_sample_points = 1500;  // source points scored by the distance field

  // --- ICP (paper III-A-1: threshold starts large and shrinks) ---
  // First threshold; 0 = automatic: 4 coarse voxels (12 fine voxels), the truncation of the
  // global alignment's distance field.
  double max_correspondence_m = 0.0;
  // Last threshold; 0 = automatic: 1.2 fine voxels, at least 0.1 m. A tight last threshold matters on
  // real data: slowly moving objects and sensor artefacts bias the motion at 0.25 m (KITTI chains
  // a->b->c vs a->c disagreed by up to 2.7 cm at 3 voxels, 8 mm at 0.1 m).
  double min_correspondence_m = 0.0;
  double threshold_shrink = 0.5;  // threshold *= this after each level converged
  int max_iterations_per_level = 15;
  double convergence_rotation_rad = 1e-5;  // a level ends when an update is smaller than both
  double convergence_translation_m = 1e-4;

  // --- acceptance ---
  double min_fitness = 0.2;                // inlier ratio of the source at the last threshold
  double max_free_space_violation = 0.15;  // share of source points lying in space scan i saw empty
  // Degenerate geometry below this conditioning of the Hessian (lambda_min / lambda_max, rotation scaled
  // by the RMS range): a single plane, a corridor.
  double min_conditioning = 1e-3;

  // OpenMP threads; 0 = all cores. 1 by default: the pipeline runs several processes on few cores, and
  // OpenMP threads that spin at barriers on a loaded machine made a registration 5x slower (measured
  // with bench_lidar_icp on 2 shared cores: 1.05 s with 2 threads, 0.21 s with 1).
  int num_threads = 1;

  // Empty when the settings are usable, else what is wrong (names the field).
  std::string Validate() const;
};

// Why a registration is not usable.
enum class RegistrationFailure {
  kNone,                // usable
  kNotRun,              // a default-constructed result
  kInvalidSettings,     // settings.Validate() failed
  kInvalidGuess,        // the initial guess is not a rigid transform
  kTooFewPoints,        // too few valid points before or after downsampling (min_points)
  kNoCandidate,         // the global alignment found no candidate pose
  kTooFewInliers,       // too few source points with a planar target point at the last threshold
  kLowFitness,          // inlier ratio below min_fitness
  kFreeSpaceViolation,  // too many points in space scan i saw empty (max_free_space_violation)
  kDegenerate,          // the geometry leaves a direction of the motion unconstrained
  kNotConverged,        // ICP did not settle at the last threshold
  kInternalError,       // an exception inside the core
};

struct RegistrationResult {
  // Maps points of scan j into the frame of scan i. When not usable, the last estimate (if any): do not
  // use it.
  Isometry3 T_li_lj = Isometry3::Identity();
  // Accepted: ICP settled and every check passed (what `fusecal register` prints as "converged").
  bool usable() const { return failure_reason.code == RegistrationFailure::kNone; }
  double fitness = 0.0;       // inlier ratio of the (downsampled) source at the last threshold
  double inlier_rms_m = 0.0;  // RMS point-to-plane distance of the inliers
  int iterations = 0;         // Gauss-Newton iterations, all levels and candidates
  // Covariance of the right perturbation d = [omega (rad); nu (m)], T_true = T_li_lj * Exp(d), from the
  // Gauss-Newton Hessian scaled by the residual variance: sigma^2 H^-1.
  Matrix6 covariance = Matrix6::Zero();
  double seconds = 0.0;
  Failure<RegistrationFailure> failure_reason{RegistrationFailure::kNotRun, {}};  // text empty when usable

  // Diagnostics.
  size_t source_points = 0;  // fine source points used (scan j)
  size_t target_points = 0;  // fine target points used (scan i)
  size_t inliers = 0;
  double free_space_violation = 0.0;  // share of source points in space scan i observed as empty
  double voxel_size_m = 0.0;          // fine voxel size used
  double global_score = 0.0;          // global-alignment objective of the chosen candidate, in [-1, 1]
  double conditioning = 0.0;          // lambda_min / lambda_max of the scaled Hessian (see settings)
};

// Registers scan_j (source) to scan_i (target) with no initial guess. Never throws.
RegistrationResult Register(const PointCloud& scan_i, const PointCloud& scan_j,
                            const RegistrationSettings& settings = RegistrationSettings());

// With a guess of T_li_lj: when settings.global_alignment is true (the default) the guess is one more
// candidate next to the global search's, and the best one wins; when false, ICP starts from the guess
// alone. Never throws.
RegistrationResult RegisterWithGuess(const PointCloud& scan_i, const PointCloud& scan_j, const Isometry3& guess_T_li_lj,
                                     const RegistrationSettings& settings = RegistrationSettings());

}  // namespace fusecal::lidar_icp
