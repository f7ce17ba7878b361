// Settings of the camera front end (paper section III-A-1): plain structs with defaults, checked by
// Validate().
//
// Angular thresholds are given in pixels and converted to angles with the angular size of one pixel at the
// image centre of the camera model (bearings.hpp, PixelAngleRad), so that one set of defaults fits a
// 1242-pixel pinhole image and a 2048-pixel panorama alike.
#pragma once

#include <string>

namespace fusecal {

struct FeatureSettings {
  // Feature budget per image: the strongest AKAZE responses are kept, spread over a grid of
  // grid_cols x grid_rows cells (each cell first gets an equal share, the rest goes to the strongest left).
  int max_features = 2500;
  int grid_cols = 16;
  int grid_rows = 8;
  // cv::AKAZE detector response threshold, number of octaves and of sublevels per octave.
  double akaze_threshold = 0.0005;
  int akaze_octaves = 4;
  int akaze_octave_layers = 4;
  // AKAZE runs on the grey image scaled by this (cv::INTER_AREA); keypoints are mapped back to pixels of
  // the full image before they are unprojected. 1: full resolution. AKAZE's cost grows with the pixel
  // count: 0.5 extracts a 2048x1024 panorama about 3x faster (tools/bench-realtime).
  double detection_scale = 1.0;

  // Equirectangular only: no features beyond this |latitude| (the poles are stretched along the rows, so
  // descriptors there are unreliable); columns are padded by wrap-around so features on the seam see their
  // full neighbourhood.
  double max_abs_latitude_deg = 70.0;
  int seam_padding_px = 48;

  // Blank areas (regions of constant grey value blank_value, e.g. the unexposed part of a panorama or the
  // black border of a rectified image) and blank_margin_px around them get no features; -1 disables.
  int blank_value = 0;
  int blank_margin_px = 8;

  std::string Validate() const;
};

struct MatchingSettings {
  // Lowe's ratio test on the two nearest Hamming neighbours, then a mutual (cross) check.
  double ratio = 0.8;
  bool mutual_check = true;
  std::string Validate() const;
};

struct RansacSettings {
  // Minimal solver of the 5-point RANSAC on bearing vectors (OpenGV): "stewenius" or "nister".
  std::string algorithm = "stewenius";
  // Inlier threshold: angle between a bearing and its reprojection, in pixels at the image centre.
  double threshold_px = 1.5;
  int max_iterations = 2000;
  double probability = 0.999;
  std::string Validate() const;
};

struct RefinementSettings {
  // Scale of the Cauchy loss on the angular epipolar error, in pixels at the image centre.
  double loss_scale_px = 1.0;
  int max_iterations = 50;
  // Inliers are re-selected with the refined motion and refined again, this many rounds in all.
  int rounds = 2;
  bool compute_covariance = true;
  std::string Validate() const;
};

struct CameraFrontendSettings {
  FeatureSettings features;
  MatchingSettings matching;
  RansacSettings ransac;
  RefinementSettings refinement;

  // Fewer inliers than this: too_few_inliers, the motion is not valid.
  int min_inliers = 30;

  // Near-pure rotation (translation direction unreliable; the rotation stays valid). The rotation-only model
  // f_i = R f_j is fitted to the inliers; the translation is unreliable when the median angle it leaves
  // (the parallax) is below min_parallax_px pixels, or below parallax_noise_ratio times the median angular
  // epipolar error (i.e. the translation explains no more than noise), or when the standard deviation of
  // the translation direction exceeds max_translation_std_deg.
  double min_parallax_px = 0.5;
  double parallax_noise_ratio = 4.0;
  double max_translation_std_deg = 5.0;

  // Empty when valid, else a message naming the first offending field ("ransac.threshold_px: ...").
  std::string Validate() const;
};

}  // namespace fusecal
