#include "stages/stationarity/settings.hpp"

#include <cmath>

namespace fusecal {

namespace {
bool Positive(double v) { return std::isfinite(v) && v > 0; }
bool NonNegative(double v) { return std::isfinite(v) && v >= 0; }
std::string Prefixed(const std::string& prefix, const std::string& problem) {
  return problem.empty() ? problem : prefix + problem;
}
}  // namespace

std::string ImageMotionSettings::Validate() const {
  if (working_width_px < 32 || working_width_px > 8192) return "working_width_px: must be in [32, 8192]";
  if (max_corners < 8) return "max_corners: must be at least 8";
  if (!(corner_quality > 0 && corner_quality < 1)) return "corner_quality: must be in (0, 1)";
  if (klt_window_px < 5 || klt_window_px % 2 == 0) return "klt_window_px: must be odd and at least 5";
  if (klt_pyramid_levels < 0 || klt_pyramid_levels > 8) return "klt_pyramid_levels: must be in [0, 8]";
  if (!Positive(max_forward_backward_px)) return "max_forward_backward_px: must be positive";
  if (min_tracks < 3) return "min_tracks: must be at least 3";
  if (min_tracks > max_corners) return "min_tracks: must not exceed max_corners";
  if (!(min_tracked_fraction >= 0 && min_tracked_fraction <= 1)) return "min_tracked_fraction: must be in [0, 1]";
  if (!NonNegative(min_contrast)) return "min_contrast: must not be negative";
  if (!Positive(still_flow_px)) return "still_flow_px: must be positive";
  if (!Positive(max_drift_px)) return "max_drift_px: must be positive";
  return {};
}

std::string LidarChangeSettings::Validate() const {
  if (!(azimuth_bin_deg >= 0.05 && azimuth_bin_deg <= 45)) return "azimuth_bin_deg: must be in [0.05, 45]";
  if (!(elevation_bin_deg >= 0.05 && elevation_bin_deg <= 45)) return "elevation_bin_deg: must be in [0.05, 45]";
  if (max_rings < 1 || max_rings > 1024) return "max_rings: must be in [1, 1024]";
  if (!NonNegative(min_range_m)) return "min_range_m: must not be negative";
  if (!Positive(max_range_m) || max_range_m <= min_range_m) return "max_range_m: must exceed min_range_m";
  if (min_valid_cells < 1) return "min_valid_cells: must be at least 1";
  if (!(change_quantile >= 0 && change_quantile <= 1)) return "change_quantile: must be in [0, 1]";
  if (!(max_ring_elevation_std_deg > 0)) return "max_ring_elevation_std_deg: must be positive";
  if (!(patch_deg >= azimuth_bin_deg && patch_deg >= elevation_bin_deg && patch_deg <= 90))
    return "patch_deg: must be at least a cell and at most 90";
  if (patch_min_cells < 1) return "patch_min_cells: must be at least 1";
  if (min_patches < 1) return "min_patches: must be at least 1";
  if (!Positive(still_change_m)) return "still_change_m: must be positive";
  if (!Positive(max_drift_m)) return "max_drift_m: must be positive";
  return {};
}

std::string StationaritySettings::Validate() const {
  if (auto p = Prefixed("image.", image.Validate()); !p.empty()) return p;
  if (auto p = Prefixed("lidar.", lidar.Validate()); !p.empty()) return p;
  if (!Positive(min_still_s)) return "min_still_s: must be positive";
  if (!NonNegative(max_pair_dt_s)) return "max_pair_dt_s: must not be negative";
  if (!NonNegative(pair_tie_s)) return "pair_tie_s: must not be negative";
  if (merge_scans < 1 || merge_scans > 32) return "merge_scans: must be in [1, 32]";
  if (!(accumulate_s >= 0 && accumulate_s <= 60)) return "accumulate_s: must be in [0, 60]";
  if (max_station_points < 1000 || max_station_points > 20000000)
    return "max_station_points: must be in [1000, 20000000]";
  if (!Positive(moved_flow_px)) return "moved_flow_px: must be positive";
  if (!Positive(moved_change_m)) return "moved_change_m: must be positive";
  if (!Positive(max_frame_gap_s)) return "max_frame_gap_s: must be positive";
  if (!Positive(sensor_timeout_s)) return "sensor_timeout_s: must be positive";
  if (max_buffered_frames < 2) return "max_buffered_frames: must be at least 2";
  if (max_buffered_frames < merge_scans) return "max_buffered_frames: must be at least merge_scans";
  return {};
}

}  // namespace fusecal
