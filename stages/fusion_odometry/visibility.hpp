// Step 1 of the fusion odometry (paper III-B-1, "the point cloud of station i is projected onto image i
// with the current extrinsic"): which scan points camera i actually sees.
//
// The LiDAR sees the scene from its own viewpoint and between its sparse beams, so a plain projection
// lets camera i "see through" foreground objects: background points land on foreground pixels. A z-buffer
// over small cells keeps the nearest range per cell. A point is hidden when a point in its own cell is
// clearly closer, or when it lies clearly behind its surroundings: for the pairs of cells mirrored about
// it within occlusion_radius_px, the second difference of the range
//   s = (r_near(+o) + r_near(-o)) / 2 - r_point
// is clearly negative (a seen-through point has nearer surfaces around it). A slanted surface (a floor or
// road seen at a grazing angle) changes its range linearly across the image, s ~ 0, and stays visible,
// which a plain "nearest range nearby" test would wrongly hide.
#pragma once

#include <limits>
#include <map>
#include <vector>

#include "stages/foundation/camera_model.hpp"
#include "stages/foundation/point_cloud.hpp"
#include "stages/foundation/se3.hpp"
#include "stages/fusion_odometry/settings.hpp"
#include "stages/fusion_odometry/types.hpp"

namespace fusecal::fusion_odometry {

// Smallest and largest range per cell of cell_px x cell_px pixels. Columns wrap for panoramas.
class DepthGrid {
 public:
  DepthGrid() = default;
  DepthGrid(int width, int height, int cell_px, bool wrap);

  void Insert(const Eigen::Vector2d& pixel, double range);

  // Smallest range in the cell of the pixel (+inf when empty).
  double OwnMin(const Eigen::Vector2d& pixel) const;

  // Extremes of the second difference s = (near(+o) + near(-o)) / 2 - range over the pairs of non-empty
  // cells mirrored about the pixel's cell within radius_px (near: smallest range of a cell). Both 0 when
  // no pair has two non-empty cells.
  struct Contrast {
    double most_negative = 0.0;  // < 0: the point lies behind its surroundings (hidden)
    double most_positive = 0.0;  // > 0: the point lies in front of something (a silhouette, a depth edge)
  };
  Contrast SecondDifference(const Eigen::Vector2d& pixel, double range, double radius_px) const;

 private:
  int Col(double u) const;
  int Row(double v) const;
  float Near(int row, int col) const;  // +inf outside the rows or for an empty cell; columns wrap
  struct PairExtremes {
    bool computed = false, any = false;
    double lowest = std::numeric_limits<double>::infinity();
    double highest = -std::numeric_limits<double>::infinity();
  };
  const PairExtremes& CellPairs(int row, int col, int k) const;

  int cell_px_ = 1, cols_ = 0, rows_ = 0;
  bool wrap_ = false;
  std::vector<float> min_;
  // Per neighbourhood size k: the pair extremes of each cell, filled on first use (Insert clears them).
  mutable std::map<int, std::vector<PairExtremes>> pair_memo_;
};

struct VisibleScan {
  std::vector<ScanPoint> points;  // visible points
  int projected = 0;              // points that projected into image i within the range limits
  DepthGrid grid;                 // z-buffer of all projected points
};

// Projects scan_i into camera i with X = T_camera_lidar and keeps the visible points. Non-finite points
// are skipped.
VisibleScan ProjectVisible(const PointCloud& scan_i, const CameraModel& camera, const Isometry3& T_camera_lidar,
                           const VisibilitySettings& settings);

}  // namespace fusecal::fusion_odometry
