// Settings of the sensor fusion odometry (Ishikawa, Oishi, Ikeuchi, IROS 2018, section III-B-1): plain
// structs with defaults, each checked by Validate() (empty string when usable, else the offending field).
//
// Angular thresholds are given in pixels and converted to angles with the angle subtended by one pixel at
// the image centre (PixelAngleRad in types.hpp), so that one set of defaults fits a 1242-pixel pinhole image
// and a 2048-pixel panorama alike.
#pragma once

#include <string>

namespace fusecal::fusion_odometry {

// Which scan points image i sees (visibility.hpp). A z-buffer over cells of cell_px x cell_px pixels keeps
// the smallest camera-frame range per cell; a point is hidden when a point in its cell is closer than
// (1 - occlusion_tolerance) times its range, or when it lies more than occlusion_tolerance times its range
// behind the mean of two mirrored cells within occlusion_radius_px, so that LiDAR points the camera cannot
// see (behind a foreground object, seen by the LiDAR from its own viewpoint or between its sparse beams)
// are not "seen through".
struct VisibilitySettings {
  double min_range_m = 0.5;  // camera-frame range limits of the points used
  double max_range_m = 150.0;
  int cell_px = 4;
  double occlusion_radius_px = 6.0;
  double occlusion_tolerance = 0.1;
  std::string Validate() const;
};

// Which visible points are tracked (track_selection.hpp): trackable places only (Shi-Tomasi minimum
// eigenvalue of the gradient structure tensor at the projected pixel at least min_corner_quality times the
// strongest response among the candidates), away from depth edges, at least min_distance_px apart, the
// strongest first, at most max_points.
struct SelectionSettings {
  int max_points = 1500;
  double min_distance_px = 4.0;
  int corner_block_size = 7;         // window of the structure tensor (cv::cornerMinEigenVal)
  double min_corner_quality = 0.02;  // relative to the strongest candidate response
  // Foreground silhouettes: a point lying more than depth_edge_tolerance times its range in front of the
  // mean of two mirrored cells within depth_edge_radius_px is on a depth edge (its tracking window mixes
  // two motions); 0 disables. Slanted surfaces (linear change of range) are not edges.
  double depth_edge_radius_px = 6.0;
  double depth_edge_tolerance = 0.1;
  double max_abs_latitude_deg = 75.0;  // equirectangular only: stretched rows near the poles are skipped
  std::string Validate() const;
};

// Pyramidal KLT from image i into image j (klt_tracking.hpp), with the initial flow predicted from the
// motion guess, and a forward-backward check.
struct TrackingSettings {
  int window_px = 15;  // odd; small windows suffer less from scale change and depth edges
  // Each forward track is refined at full resolution with a smaller window of about this angle (degrees;
  // 0: never), when that is narrower than window_px. A translation-only window averages the flow over its
  // area; where the flow field curves (translation flow ~ sin of the angle to the direction of travel,
  // over depth) the average falls short of the flow at the centre by a term growing with the window's
  // angular area. Measured at the true extrinsic, camera motions too short by: 0.128 % with 15 px on a
  // 1024-wide panorama (5.3 deg), 0.028 % with 7 px (2.5 deg); 0.007 % with 15 px on a 2048-wide one
  // (2.6 deg), where refining changes nothing (docs/benchmarks.md, "KLT window and the length of camera motions").
  double refine_window_deg = 2.5;
  int pyramid_levels = 3;
  int max_iterations = 30;
  double epsilon_px = 0.01;
  double min_eigen_threshold = 1e-4;  // cv::calcOpticalFlowPyrLK minEigThreshold
  // Tracking j back into i must land within this distance of the start.
  double max_forward_backward_px = 0.5;
  // Rotation compensation (derotation.hpp): when the predicted rotation exceeds derotate_min_deg, image j
  // is resampled with camera i's orientation before tracking (negative: never). The resampling map is
  // evaluated exactly every derotation_grid_px pixels and interpolated in between.
  double derotate_min_deg = 1.0;
  int derotation_grid_px = 8;
  std::string Validate() const;
};

// P3P RANSAC on bearing vectors (Kneip et al., CVPR 2011; OpenGV), used when there is no reliable guess.
struct RansacSettings {
  double threshold_px = 2.0;  // angle between a bearing and the reprojected point
  int max_iterations = 1000;
  double probability = 0.999;
  std::string Validate() const;
};

// Minimisation of the angular error sum |v'_j x Proj(p_cj)| (paper eq. in III-B-1) with a robust loss;
// after each round the tracks are re-classified by their residual under the refined pose (tracks on objects
// that move with the car, e.g. vehicles in traffic, end up outside), and the inliers refined again.
struct RefinementSettings {
  std::string loss = "cauchy";  // "cauchy", "huber" or "none"
  double loss_scale_px = 1.0;
  double max_residual_px = 2.0;  // inlier threshold of the final classification
  int rounds = 3;
  int max_iterations = 50;
  bool compute_covariance = true;
  std::string Validate() const;
};

struct FusionOdometrySettings {
  VisibilitySettings visibility;
  SelectionSettings selection;
  TrackingSettings tracking;
  RansacSettings ransac;
  RefinementSettings refinement;

  // When to run the P3P RANSAC: "auto": unless the guess is marked reliable and at least
  // min_guess_inlier_ratio of the tracks agree with it; "always"; "never" (the guess is the start).
  std::string ransac_mode = "auto";
  double min_guess_inlier_ratio = 0.5;
  // After a RANSAC pass, track again with the estimated motion as the predicted flow (recovers tracks a
  // poor guess lost) and refine again.
  bool retrack = true;

  // Fewer final inliers than this, or a smaller share of the tracks: the motion has not converged.
  int min_inliers = 20;
  double min_inlier_ratio = 0.3;

  std::string Validate() const;
};

}  // namespace fusecal::fusion_odometry
