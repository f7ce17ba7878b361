// Truncated distance field of a scan on a dense voxel grid, for fast scoring of many candidate poses in
// the global alignment: near a surface the value is 1 - d / truncation (d = distance to the nearest
// occupied voxel centre); in space the scan saw through (between its sensor and its returns, farther
// than the truncation from the return) it is -free_space_penalty; elsewhere (unobserved, occluded) 0.
// The free-space term matters when the two scans overlap only partly (a tilted multi-beam LiDAR sees
// the ceiling where the other saw nothing): points outside the target's view are neutral, so a wrong
// pose cannot gain by pushing them into observed space, and points in observed free space count against.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

namespace fusecal::lidar_icp {

class DistanceField {
 public:
  // The grid covers the points' bounding box plus the truncation; when it would exceed max_cells the
  // resolution is coarsened until it fits.
  // `points` are in the frame of their sensor (the sensor is at the origin).
  DistanceField(const std::vector<Eigen::Vector3f>& points, float resolution_m, float truncation_m,
                float free_space_penalty = 0.5f, size_t max_cells = size_t(24) << 20);

  float resolution() const { return resolution_; }
  float truncation() const { return truncation_; }

  // Mean field value over `points` mapped by (R, t), in [-free_space_penalty, 1].
  float Score(const Eigen::Matrix3f& R, const Eigen::Vector3f& t, const std::vector<Eigen::Vector3f>& points) const;

  // Sum of the values (in units of 1) and the number of points that fell in observed cells (near a
  // surface or in free space).
  struct Tally {
    float sum = 0.0f;
    int observed = 0;
  };
  Tally Evaluate(const Eigen::Matrix3f& R, const Eigen::Vector3f& t, const std::vector<Eigen::Vector3f>& points) const;

 private:
  // Calls visit(cell value) for every point that (R, t) maps inside the grid. Inlined into both
  // callers, so the global search's hot loop stays a plain loop.
  template <typename Visit>
  void ForEachCell(const Eigen::Matrix3f& R, const Eigen::Vector3f& t, const std::vector<Eigen::Vector3f>& points,
                   Visit visit) const {
    const float inv = 1.0f / resolution_;
    const Eigen::Matrix3f Rs = R * inv;
    const Eigen::Vector3f ts = (t - origin_) * inv;
    for (const Eigen::Vector3f& p : points) {
      const Eigen::Vector3f c = Rs * p + ts;
      const int x = static_cast<int>(c.x()), y = static_cast<int>(c.y()), z = static_cast<int>(c.z());
      // c may be negative: int() truncates toward zero, so also reject c < 0 explicitly.
      if (c.x() < 0 || c.y() < 0 || c.z() < 0 || x >= nx_ || y >= ny_ || z >= nz_) continue;
      visit(cells_[(size_t(z) * ny_ + size_t(y)) * nx_ + size_t(x)]);
    }
  }

  float resolution_;
  float truncation_;
  Eigen::Vector3f origin_;
  int nx_ = 0, ny_ = 0, nz_ = 0;
  std::vector<int8_t> cells_;  // value * 127
};

}  // namespace fusecal::lidar_icp
