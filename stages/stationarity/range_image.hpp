// LiDAR change between two scans on a coarse range image: a quantile (default the median) of the absolute
// range difference over the cells valid in both. Cheap (one pass over the points), independent of point
// order and count, and robust to objects moving around a still rig.
// Irregular points (no beams, e.g. a non-repetitive LiDAR): two scans sample other directions inside each
// cell, so a cell's difference is range noise (twice its variance) plus sampling, at the level of any
// still threshold; a motion shifts the ranges of whole regions the same way. The change is then the
// quantile of |median signed difference| over patches of patch_deg x patch_deg, which averages the noise
// down and keeps the motion.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "stages/foundation/point_cloud.hpp"
#include "stages/foundation/stage_result.hpp"
#include "stages/stationarity/settings.hpp"

namespace fusecal {

struct RangeImage {
  int rows = 0, cols = 0;
  bool by_ring = false;      // rows are beams (ring field), else elevation bins
  std::vector<float> range;  // row-major; +inf where empty
  int valid_cells = 0;
  size_t valid_points = 0;  // finite points within [min_range_m, max_range_m]
};

// True when the ring field names beams of a fixed elevation, as on spinning multi-beam LiDARs: every point
// has a ring in [0, max_rings) and the points of each ring within [min_range_m, max_range_m] lie within
// max_ring_elevation_std_deg (a standard deviation) of one elevation. The "line" of a non-repetitive LiDAR (Livox)
// sweeps the whole field of view: not a beam.
bool RingsAreBeams(const PointCloud& cloud, const LidarChangeSettings& settings);

// Rows by ring when RingsAreBeams, else by elevation. Points with a non-finite coordinate or a range
// outside [min_range_m, max_range_m] are skipped.
RangeImage BuildRangeImage(const PointCloud& cloud, const LidarChangeSettings& settings);

// Why a LiDAR change cannot decide.
enum class LidarChangeFailure {
  kNone,               // usable
  kNotRun,             // a default-constructed result
  kLayoutsDiffer,      // the range images differ in layout (ring field in one scan only)
  kTooFewCommonCells,  // fewer cells valid in both than min_valid_cells
};

struct LidarChange {
  bool usable() const { return failure_reason.code == LidarChangeFailure::kNone; }
  double change_m = 0;  // change_quantile of |range difference| (of cells, or of patches), metres
  int common_cells = 0;
  Failure<LidarChangeFailure> failure_reason{LidarChangeFailure::kNotRun, {}};
};

LidarChange CompareRangeImages(const RangeImage& a, const RangeImage& b, const LidarChangeSettings& settings);

}  // namespace fusecal
