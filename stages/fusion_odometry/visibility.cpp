#include "stages/fusion_odometry/visibility.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fusecal::fusion_odometry {

DepthGrid::DepthGrid(int width, int height, int cell_px, bool wrap)
    : cell_px_(std::max(1, cell_px)),
      cols_((width + cell_px_ - 1) / cell_px_),
      rows_((height + cell_px_ - 1) / cell_px_),
      wrap_(wrap),
      min_(static_cast<size_t>(cols_) * rows_, std::numeric_limits<float>::infinity()) {}

int DepthGrid::Col(double u) const {
  return std::clamp(static_cast<int>(std::floor((u + 0.5) / cell_px_)), 0, cols_ - 1);
}

int DepthGrid::Row(double v) const {
  return std::clamp(static_cast<int>(std::floor((v + 0.5) / cell_px_)), 0, rows_ - 1);
}

float DepthGrid::Near(int row, int col) const {
  if (row < 0 || row >= rows_) return std::numeric_limits<float>::infinity();
  if (wrap_) col = ((col % cols_) + cols_) % cols_;
  if (col < 0 || col >= cols_) return std::numeric_limits<float>::infinity();
  return min_[static_cast<size_t>(row) * cols_ + col];
}

void DepthGrid::Insert(const Eigen::Vector2d& pixel, double range) {
  if (cols_ == 0 || rows_ == 0) return;
  pair_memo_.clear();
  float& cell = min_[static_cast<size_t>(Row(pixel.y())) * cols_ + Col(pixel.x())];
  cell = std::min(cell, static_cast<float>(range));
}

double DepthGrid::OwnMin(const Eigen::Vector2d& pixel) const {
  if (cols_ == 0 || rows_ == 0) return std::numeric_limits<double>::infinity();
  return Near(Row(pixel.y()), Col(pixel.x()));
}

// The extremes of (near(+o) + near(-o)) / 2 over the mirrored pairs of one cell, computed once per cell
// and radius: every point of a cell shares them, and subtracting the point's range afterwards gives the
// same numbers as subtracting it pair by pair (rounding is monotonic).
const DepthGrid::PairExtremes& DepthGrid::CellPairs(int r0, int c0, int k) const {
  std::vector<PairExtremes>& memo = pair_memo_[k];
  if (memo.empty()) memo.resize(min_.size());
  PairExtremes& e = memo[static_cast<size_t>(r0) * cols_ + c0];
  if (e.computed) return e;
  e.computed = true;
  // Half of the offsets: (dr > 0) or (dr == 0 and dc > 0); each with its mirror.
  for (int dr = 0; dr <= k; ++dr) {
    for (int dc = -k; dc <= k; ++dc) {
      if (dr == 0 && dc <= 0) continue;
      const float a = Near(r0 + dr, c0 + dc), b = Near(r0 - dr, c0 - dc);
      if (!std::isfinite(a) || !std::isfinite(b)) continue;
      const double mean = 0.5 * (static_cast<double>(a) + b);
      e.any = true;
      e.lowest = std::min(e.lowest, mean);
      e.highest = std::max(e.highest, mean);
    }
  }
  return e;
}

DepthGrid::Contrast DepthGrid::SecondDifference(const Eigen::Vector2d& pixel, double range, double radius_px) const {
  Contrast out;
  if (cols_ == 0 || rows_ == 0) return out;
  const int r0 = Row(pixel.y()), c0 = Col(pixel.x());  // clamped into the grid
  const PairExtremes& e = CellPairs(r0, c0, static_cast<int>(std::ceil(radius_px / cell_px_)));
  if (!e.any) return out;
  out.most_negative = std::min(0.0, e.lowest - range);
  out.most_positive = std::max(0.0, e.highest - range);
  return out;
}

VisibleScan ProjectVisible(const PointCloud& scan_i, const CameraModel& camera, const Isometry3& T_camera_lidar,
                           const VisibilitySettings& settings) {
  VisibleScan out;
  out.grid = DepthGrid(camera.width(), camera.height(), settings.cell_px, camera.WrapsHorizontally());
  const Eigen::Matrix3d R = T_camera_lidar.linear();
  const Eigen::Vector3d t = T_camera_lidar.translation();

  std::vector<ScanPoint> projected;
  projected.reserve(scan_i.size());
  for (size_t k = 0; k < scan_i.size(); ++k) {
    const Eigen::Vector3f& p = scan_i.points[k];
    if (!p.allFinite()) continue;
    ScanPoint s;
    s.p_ci = R * p.cast<double>() + t;  // p_ci = X p_li
    s.range = s.p_ci.norm();
    if (s.range < settings.min_range_m || s.range > settings.max_range_m) continue;
    if (!camera.Project(s.p_ci, &s.pixel_i) || !camera.InImage(s.pixel_i)) continue;
    s.index = static_cast<int>(k);
    out.grid.Insert(s.pixel_i, s.range);
    projected.push_back(s);
  }
  out.projected = static_cast<int>(projected.size());

  // Hidden: a clearly closer point in the same cell, or clearly behind its surroundings.
  const double tol = settings.occlusion_tolerance;
  out.points.reserve(projected.size());
  for (const ScanPoint& s : projected) {
    if (out.grid.OwnMin(s.pixel_i) < (1.0 - tol) * s.range) continue;
    if (out.grid.SecondDifference(s.pixel_i, s.range, settings.occlusion_radius_px).most_negative < -tol * s.range)
      continue;
    out.points.push_back(s);
  }
  return out;
}

}  // namespace fusecal::fusion_odometry
