#include "stages/fusion_odometry/settings.hpp"

#include <cmath>

namespace fusecal::fusion_odometry {

namespace {
bool Positive(double v) { return std::isfinite(v) && v > 0; }
bool NonNegative(double v) { return std::isfinite(v) && v >= 0; }
bool InOpenUnit(double v) { return std::isfinite(v) && v > 0 && v < 1; }
}  // namespace

std::string VisibilitySettings::Validate() const {
  if (!NonNegative(min_range_m)) return "min_range_m: must not be negative";
  if (!(Positive(max_range_m) && max_range_m > min_range_m)) return "max_range_m: must exceed min_range_m";
  if (cell_px < 1 || cell_px > 64) return "cell_px: must be in [1, 64]";
  if (!NonNegative(occlusion_radius_px) || occlusion_radius_px > 256) return "occlusion_radius_px: must be in [0, 256]";
  if (!InOpenUnit(occlusion_tolerance)) return "occlusion_tolerance: must be in (0, 1)";
  return {};
}

std::string SelectionSettings::Validate() const {
  if (max_points < 4) return "max_points: must be at least 4";
  if (!NonNegative(min_distance_px)) return "min_distance_px: must not be negative";
  if (corner_block_size < 2 || corner_block_size > 31) return "corner_block_size: must be in [2, 31]";
  if (!(std::isfinite(min_corner_quality) && min_corner_quality >= 0 && min_corner_quality < 1))
    return "min_corner_quality: must be in [0, 1)";
  if (!NonNegative(depth_edge_radius_px) || depth_edge_radius_px > 256)
    return "depth_edge_radius_px: must be in [0, 256]";
  if (!Positive(depth_edge_tolerance)) return "depth_edge_tolerance: must be positive";
  if (!(max_abs_latitude_deg > 0 && max_abs_latitude_deg <= 90)) return "max_abs_latitude_deg: must be in (0, 90]";
  return {};
}

std::string TrackingSettings::Validate() const {
  if (window_px < 5 || window_px > 101 || window_px % 2 == 0) return "window_px: must be odd, in [5, 101]";
  if (!(refine_window_deg >= 0 && refine_window_deg <= 90)) return "refine_window_deg: must be in [0, 90]";
  if (pyramid_levels < 0 || pyramid_levels > 8) return "pyramid_levels: must be in [0, 8]";
  if (max_iterations < 1) return "max_iterations: must be at least 1";
  if (!Positive(epsilon_px)) return "epsilon_px: must be positive";
  if (!NonNegative(min_eigen_threshold)) return "min_eigen_threshold: must not be negative";
  if (!Positive(max_forward_backward_px)) return "max_forward_backward_px: must be positive";
  if (!std::isfinite(derotate_min_deg)) return "derotate_min_deg: must be finite";
  if (derotation_grid_px < 1 || derotation_grid_px > 64) return "derotation_grid_px: must be in [1, 64]";
  return {};
}

std::string RansacSettings::Validate() const {
  if (!Positive(threshold_px)) return "threshold_px: must be positive";
  if (max_iterations < 1) return "max_iterations: must be at least 1";
  if (!InOpenUnit(probability)) return "probability: must be in (0, 1)";
  return {};
}

std::string RefinementSettings::Validate() const {
  if (loss != "cauchy" && loss != "huber" && loss != "none")
    return "loss: must be cauchy, huber or none, got '" + loss + "'";
  if (!Positive(loss_scale_px)) return "loss_scale_px: must be positive";
  if (!Positive(max_residual_px)) return "max_residual_px: must be positive";
  if (rounds < 1 || rounds > 10) return "rounds: must be in [1, 10]";
  if (max_iterations < 1) return "max_iterations: must be at least 1";
  return {};
}

std::string FusionOdometrySettings::Validate() const {
  if (std::string e = visibility.Validate(); !e.empty()) return "visibility." + e;
  if (std::string e = selection.Validate(); !e.empty()) return "selection." + e;
  if (std::string e = tracking.Validate(); !e.empty()) return "tracking." + e;
  if (std::string e = ransac.Validate(); !e.empty()) return "ransac." + e;
  if (std::string e = refinement.Validate(); !e.empty()) return "refinement." + e;
  if (ransac_mode != "auto" && ransac_mode != "always" && ransac_mode != "never")
    return "ransac_mode: must be auto, always or never, got '" + ransac_mode + "'";
  if (!(std::isfinite(min_guess_inlier_ratio) && min_guess_inlier_ratio >= 0 && min_guess_inlier_ratio <= 1))
    return "min_guess_inlier_ratio: must be in [0, 1]";
  if (min_inliers < 6) return "min_inliers: must be at least 6";
  if (!(std::isfinite(min_inlier_ratio) && min_inlier_ratio >= 0 && min_inlier_ratio <= 1))
    return "min_inlier_ratio: must be in [0, 1]";
  return {};
}

}  // namespace fusecal::fusion_odometry
