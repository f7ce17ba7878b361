#include "stages/lidar_icp/distance_field.hpp"

#include <algorithm>
#include <cmath>

namespace fusecal::lidar_icp {

namespace {
constexpr int kMax = 127;
}

DistanceField::DistanceField(const std::vector<Eigen::Vector3f>& points, float resolution_m, float truncation_m,
                             float free_space_penalty, size_t max_cells)
    : resolution_(resolution_m), truncation_(truncation_m), origin_(Eigen::Vector3f::Zero()) {
  if (points.empty()) return;
  Eigen::Vector3f lo = Eigen::Vector3f::Zero(), hi = Eigen::Vector3f::Zero();  // include the sensor
  for (const Eigen::Vector3f& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  int radius = 0;
  for (;;) {
    radius = std::max(1, static_cast<int>(std::ceil(truncation_ / resolution_)));
    origin_ = lo - Eigen::Vector3f::Constant((radius + 1) * resolution_);
    const Eigen::Vector3f extent = hi - origin_ + Eigen::Vector3f::Constant((radius + 1) * resolution_);
    nx_ = static_cast<int>(std::ceil(extent.x() / resolution_)) + 1;
    ny_ = static_cast<int>(std::ceil(extent.y() / resolution_)) + 1;
    nz_ = static_cast<int>(std::ceil(extent.z() / resolution_)) + 1;
    if (size_t(nx_) * ny_ * nz_ <= max_cells) break;
    resolution_ *= 1.25f;
  }
  cells_.assign(size_t(nx_) * ny_ * nz_, 0);
  const float inv = 1.0f / resolution_;
  auto index_of = [&](const Eigen::Vector3f& p) {
    const Eigen::Vector3f c = (p - origin_) * inv;
    return (size_t(c.z()) * ny_ + size_t(c.y())) * nx_ + size_t(c.x());
  };

  // Observed free space: march from the sensor towards each return, stopping a truncation short of it.
  const auto free_value = static_cast<int8_t>(-std::lround(kMax * std::clamp(free_space_penalty, 0.0f, 1.0f)));
  if (free_value < 0) {
    const float step = 0.5f * resolution_;
    for (const Eigen::Vector3f& p : points) {
      const float range = p.norm();
      if (range <= truncation_) continue;
      const Eigen::Vector3f dir = p / range;
      for (float s = 0.0f; s < range - truncation_; s += step) cells_[index_of(s * dir)] = free_value;
    }
  }

  // Occupied cells (deduplicated through the grid itself: kMax = occupied).
  std::vector<size_t> occupied;
  for (const Eigen::Vector3f& p : points) {
    const size_t idx = index_of(p);
    if (cells_[idx] != kMax) {
      cells_[idx] = kMax;
      occupied.push_back(idx);
    }
  }
  // Splat a sphere of decreasing values around each occupied cell, keeping the maximum (so the surface
  // band overrides free space). The padding of radius+1 cells keeps every write inside the grid.
  struct Offset {
    long delta;
    int8_t value;
  };
  std::vector<Offset> offsets;
  for (int dz = -radius; dz <= radius; ++dz)
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx) {
        const float d = resolution_ * std::sqrt(float(dx * dx + dy * dy + dz * dz));
        if (d >= truncation_ || (dx == 0 && dy == 0 && dz == 0)) continue;
        const auto value = static_cast<int8_t>(std::lround(kMax * (1.0f - d / truncation_)));
        if (value <= 0) continue;
        offsets.push_back({(long(dz) * ny_ + dy) * nx_ + dx, value});
      }
  for (size_t idx : occupied)
    for (const Offset& o : offsets) {
      int8_t& cell = cells_[size_t(long(idx) + o.delta)];
      cell = std::max(cell, o.value);
    }
}

float DistanceField::Score(const Eigen::Matrix3f& R, const Eigen::Vector3f& t,
                           const std::vector<Eigen::Vector3f>& points) const {
  if (cells_.empty() || points.empty()) return 0.0f;
  int32_t sum = 0;
  ForEachCell(R, t, points, [&sum](int8_t v) { sum += v; });
  return float(sum) / (float(kMax) * float(points.size()));
}

DistanceField::Tally DistanceField::Evaluate(const Eigen::Matrix3f& R, const Eigen::Vector3f& t,
                                             const std::vector<Eigen::Vector3f>& points) const {
  Tally tally;
  if (cells_.empty() || points.empty()) return tally;
  int32_t sum = 0;
  ForEachCell(R, t, points, [&](int8_t v) {
    sum += v;
    tally.observed += v != 0;
  });
  tally.sum = float(sum) / float(kMax);
  return tally;
}

}  // namespace fusecal::lidar_icp
