#include "stages/lidar_icp/consistency.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fusecal::lidar_icp {

FreeSpaceImage::FreeSpaceImage(const std::vector<Eigen::Vector3f>& target_points, double bin_deg)
    : bin_rad_(bin_deg * M_PI / 180.0) {
  cols_ = static_cast<int>(std::ceil(2.0 * M_PI / bin_rad_));
  rows_ = static_cast<int>(std::ceil(M_PI / bin_rad_)) + 1;
  min_range_.assign(size_t(rows_) * cols_, std::numeric_limits<float>::infinity());
  for (const Eigen::Vector3f& p : target_points) {
    int r, c;
    if (Bin(p, &r, &c) < 0) continue;
    float& cell = min_range_[size_t(r) * cols_ + c];
    cell = std::min(cell, p.norm());
  }
}

int FreeSpaceImage::Bin(const Eigen::Vector3f& p, int* row, int* col) const {
  const float range = p.norm();
  if (!(range > 1e-3f)) return -1;
  const double azimuth = std::atan2(double(p.y()), double(p.x())) + M_PI;  // [0, 2pi]
  const double elevation = std::asin(std::clamp(double(p.z()) / range, -1.0, 1.0)) + 0.5 * M_PI;
  *col = std::min(cols_ - 1, static_cast<int>(azimuth / bin_rad_));
  *row = std::min(rows_ - 1, static_cast<int>(elevation / bin_rad_));
  return 0;
}

double FreeSpaceImage::ViolationRatio(const std::vector<Eigen::Vector3f>& source, const Isometry3& T,
                                      double min_range_m, double margin_m) const {
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  size_t known = 0, violations = 0;
  for (const Eigen::Vector3f& s : source) {
    const Eigen::Vector3f p = R * s + t;
    const float range = p.norm();
    int row, col;
    if (range < min_range_m || Bin(p, &row, &col) < 0) continue;
    float seen = std::numeric_limits<float>::infinity();
    for (int dr = -1; dr <= 1; ++dr) {
      const int r = row + dr;
      if (r < 0 || r >= rows_) continue;
      for (int dc = -1; dc <= 1; ++dc) {
        const int c = (col + dc + cols_) % cols_;
        seen = std::min(seen, min_range_[size_t(r) * cols_ + c]);
      }
    }
    if (!std::isfinite(seen)) continue;
    ++known;
    if (seen > range * 1.02f + float(margin_m)) ++violations;
  }
  return known == 0 ? 0.0 : double(violations) / double(known);
}

}  // namespace fusecal::lidar_icp
