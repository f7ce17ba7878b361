// LiDAR change between two scans on a coarse range image: a quantile (default the median) of the absolute
// range difference over the cells valid in both. Cheap (one pass over the points), independent of point
// order and count, and robust to objects moving around a still rig.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "foundation/point_cloud.hpp"
#include "foundation/stage_result.hpp"
#include "stationarity/settings.hpp"

namespace fusecal {

struct RangeImage {
  int rows = 0, cols = 0;
  bool by_ring = false;      // rows are beams (ring field), else elevation bins
  std::vector<float> range;  // row-major; +inf where empty
  int valid_cells = 0;
  size_t valid_points = 0;  // finite points within [min_range_m, max_range_m]
};

// Rows by ring when every point has a ring in [0, max_rings), else by elevation. Points with a non-finite
// coordinate or a range outside [min_range_m, max_range_m] are skipped.
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
  double change_m = 0;  // change_quantile of |range difference|, metres
  int common_cells = 0;
  Failure<LidarChangeFailure> failure_reason{LidarChangeFailure::kNotRun, {}};
};

LidarChange CompareRangeImages(const RangeImage& a, const RangeImage& b, const LidarChangeSettings& settings);

}  // namespace fusecal
