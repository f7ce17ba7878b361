#include "stages/camera_frontend/settings.hpp"

#include <cmath>

namespace fusecal {

namespace {
bool Positive(double v) { return std::isfinite(v) && v > 0; }
}  // namespace

std::string FeatureSettings::Validate() const {
  if (max_features < 8) return "max_features: must be at least 8";
  if (grid_cols < 1) return "grid_cols: must be at least 1";
  if (grid_rows < 1) return "grid_rows: must be at least 1";
  if (!Positive(akaze_threshold)) return "akaze_threshold: must be positive";
  if (akaze_octaves < 1 || akaze_octaves > 8) return "akaze_octaves: must be in [1, 8]";
  if (akaze_octave_layers < 1 || akaze_octave_layers > 8) return "akaze_octave_layers: must be in [1, 8]";
  if (!(detection_scale >= 0.1 && detection_scale <= 1.0)) return "detection_scale: must be in [0.1, 1]";
  if (!(max_abs_latitude_deg > 0 && max_abs_latitude_deg <= 90)) return "max_abs_latitude_deg: must be in (0, 90]";
  if (seam_padding_px < 0 || seam_padding_px > 512) return "seam_padding_px: must be in [0, 512]";
  if (blank_value < -1 || blank_value > 255) return "blank_value: must be -1 (off) or a grey value in [0, 255]";
  if (blank_margin_px < 0) return "blank_margin_px: must not be negative";
  return {};
}

std::string MatchingSettings::Validate() const {
  if (!(ratio > 0 && ratio <= 1)) return "ratio: must be in (0, 1]";
  return {};
}

std::string RansacSettings::Validate() const {
  if (algorithm != "stewenius" && algorithm != "nister")
    return "algorithm: must be stewenius or nister, got '" + algorithm + "'";
  if (!Positive(threshold_px)) return "threshold_px: must be positive";
  if (max_iterations < 1) return "max_iterations: must be at least 1";
  if (!(probability > 0 && probability < 1)) return "probability: must be in (0, 1)";
  return {};
}

std::string RefinementSettings::Validate() const {
  if (!Positive(loss_scale_px)) return "loss_scale_px: must be positive";
  if (max_iterations < 1) return "max_iterations: must be at least 1";
  if (rounds < 1) return "rounds: must be at least 1";
  return {};
}

std::string CameraFrontendSettings::Validate() const {
  if (std::string e = features.Validate(); !e.empty()) return "features." + e;
  if (std::string e = matching.Validate(); !e.empty()) return "matching." + e;
  if (std::string e = ransac.Validate(); !e.empty()) return "ransac." + e;
  if (std::string e = refinement.Validate(); !e.empty()) return "refinement." + e;
  if (min_inliers < 8) return "min_inliers: must be at least 8";
  if (!(std::isfinite(min_parallax_px) && min_parallax_px >= 0)) return "min_parallax_px: must not be negative";
  if (!(std::isfinite(parallax_noise_ratio) && parallax_noise_ratio >= 0))
    return "parallax_noise_ratio: must not be negative";
  if (!Positive(max_translation_std_deg)) return "max_translation_std_deg: must be positive";
  return {};
}

}  // namespace fusecal
