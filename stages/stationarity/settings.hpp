// Settings of the stationarity detector: plain structs with defaults, checked by Validate() (an empty
// string when valid, else "key: what is wrong").
//
// The paper (Ishikawa et al. 2018) picked its stop-and-scan stations by hand; this stage picks them from
// the streams: the rig is still while the image motion AND the LiDAR change stay below their thresholds.
//
// Image motion is measured in pixels of the image scaled to `working_width_px` wide, so that one set of
// defaults fits a 1242-pixel pinhole image and a 2048-pixel panorama alike (a panorama 640 px wide has
// 0.56 deg per pixel; a 1242 px KITTI image scaled to 640 px about 0.13 deg per pixel).
#pragma once

#include <string>

namespace fusecal {

struct ImageMotionSettings {
  // Images are converted to grey and scaled down (never up) to this width; flows are reported in pixels of
  // an image this wide.
  int working_width_px = 640;
  // Shi-Tomasi corners tracked by pyramidal KLT, forward then backward. The image is divided into a grid
  // of about max_corners cells and each cell gives its strongest corner (spread over the whole view, so
  // that an object moving in one part cannot dominate), when its minimum eigenvalue is at least
  // corner_quality times the strongest of the image.
  int max_corners = 200;
  double corner_quality = 0.01;
  int klt_window_px = 15;
  int klt_pyramid_levels = 3;
  double max_forward_backward_px = 1.0;  // a track whose backward track misses its corner by more is dropped
  // Motion is undecidable (so not still) with fewer tracks than this, or than this fraction of the corners.
  int min_tracks = 20;
  double min_tracked_fraction = 0.3;
  // A working image whose grey values have a standard deviation below this (black, blank or overexposed
  // frame) has no usable texture: image stillness cannot be decided.
  double min_contrast = 3.0;

  // Still: the median displacement between consecutive frames is at most still_flow_px AND the median
  // displacement from the first frame of the still run (the anchor) is at most max_drift_px (catches a slow
  // creep that stays below still_flow_px from frame to frame).
  double still_flow_px = 0.12;
  double max_drift_px = 0.4;

  std::string Validate() const;
};

struct LidarChangeSettings {
  // Coarse range image: columns of azimuth_bin_deg; rows are the beams (ring field) when every point has
  // a ring below max_rings, else elevation bins of elevation_bin_deg over [-90, 90] deg. A cell holds the
  // smallest range that falls into it.
  double azimuth_bin_deg = 1.0;
  double elevation_bin_deg = 0.5;
  int max_rings = 128;
  double max_ring_elevation_std_deg = 2.0;  // rings whose elevation spreads more are not beams
  double min_range_m = 1.0;                 // closer returns (the vehicle, the operator) are ignored
  double max_range_m = 200.0;
  // A scan with fewer valid cells is empty (ignored); a comparison with fewer cells valid in both is
  // undecidable (not still).
  int min_valid_cells = 100;
  // The change between two scans is this quantile (0.5: median) of |range difference| over the cells
  // valid in both: robust to cars and people moving around a stopped rig.
  double change_quantile = 0.5;
  // Irregular points (range_image.hpp): patches of patch_deg square, each with at least patch_min_cells
  // cells in common, and at least min_patches of them.
  double patch_deg = 5.0;
  int patch_min_cells = 8;
  int min_patches = 10;

  // Still: the change between consecutive scans is at most still_change_m AND the change from the first
  // scan of the still run (the anchor) is at most max_drift_m (a slow turn or tilt changes little from
  // scan to scan but accumulates).
  double still_change_m = 0.02;
  double max_drift_m = 0.03;

  std::string Validate() const;
};

struct StationaritySettings {
  ImageMotionSettings image;
  LidarChangeSettings lidar;

  // Both sensors still for at least this long (from the first still frame to the last frame of the sensor
  // that lags) -> one station.
  double min_still_s = 1.0;
  // The image and the scan of a station are the pair inside the still interval closest to each other in
  // time (among pairs within pair_tie_s of the closest, the latest), at most max_pair_dt_s apart.
  double max_pair_dt_s = 0.05;
  double pair_tie_s = 0.005;
  // Densify a multi-beam LiDAR: merge this many consecutive still scans (ending with the chosen one) into
  // the station cloud. 1: off.
  int merge_scans = 1;
  // A LiDAR without beams (a non-repetitive one: range_image.hpp's RingsAreBeams is false) covers its field
  // of view only over time: the station cloud holds every still scan of the last accumulate_s seconds up
  // to the chosen one (the still run is at least min_still_s long), at most max_station_points points.
  // 0: merge_scans as for beams.
  double accumulate_s = 1.0;
  size_t max_station_points = 1000000;

  // A new station only once the rig has moved from the previous one: the image displacement between the
  // two stations' images exceeds moved_flow_px (or tracking is lost), or the LiDAR change between their
  // scans exceeds moved_change_m.
  double moved_flow_px = 2.0;
  double moved_change_m = 0.05;

  // A sensor whose consecutive frames are further apart than this cannot be judged across the gap: its
  // still run restarts.
  double max_frame_gap_s = 0.5;
  // A sensor is reported missing when its last frame (or, never seen, the first frame of the other) lies
  // this far behind the newest frame of the other.
  double sensor_timeout_s = 1.0;
  // Bound on the frames buffered per sensor as station candidates (the frames of the current still run
  // until its station is emitted; the newest are kept).
  int max_buffered_frames = 32;

  std::string Validate() const;
};

}  // namespace fusecal
