// A fixed grid of ray directions in a sensor frame (camera sub-pixels, LiDAR beams x columns), split
// into tiles whose bounding cones are precomputed once, so that casting a frame only rotates them.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "stages/foundation/camera_model.hpp"

namespace fusecal::sim {

struct RayTile {
  int row0, row1, col0, col1;  // [row0, row1) x [col0, col1)
  Eigen::Vector3f axis;        // bounding cone, in the grid's canonical frame
  float half_rad, cos_half, sin_half;
  float spacing_rad;  // angle between neighbouring rays in the tile
};

class RayGrid {
 public:
  // direction(row, col) = frame * (cos el cos az, cos el sin az, sin el), el per row, az per column.
  static RayGrid Spherical(const std::vector<double>& elevation_rad, const std::vector<double>& azimuth_rad,
                           const Eigen::Matrix3f& frame, int tile_rows, int tile_cols);
  // Explicit unit directions, row-major rows x cols (frame = identity).
  static RayGrid Table(int rows, int cols, std::vector<Eigen::Vector3f> directions, int tile_rows, int tile_cols);

  // Direction in the canonical frame; the sensor-frame direction is frame() * Direction(row, col).
  Eigen::Vector3f Direction(int row, int col) const {
    if (table_.empty()) {
      const float ce = cos_el_[row], ca = cos_az_[col];
      return {ce * ca, ce * sin_az_[col], sin_el_[row]};
    }
    return table_[static_cast<size_t>(row) * cols_ + col];
  }
  const Eigen::Matrix3f& frame() const { return frame_; }
  int rows() const { return rows_; }
  int cols() const { return cols_; }
  const std::vector<RayTile>& tiles() const { return tiles_; }

 private:
  void MakeTiles(int tile_rows, int tile_cols);

  int rows_ = 0, cols_ = 0;
  Eigen::Matrix3f frame_ = Eigen::Matrix3f::Identity();
  std::vector<float> cos_el_, sin_el_, cos_az_, sin_az_;
  std::vector<Eigen::Vector3f> table_;
  std::vector<RayTile> tiles_;
};

// Rays of a camera: supersample x supersample per pixel at sub-pixel centres, rows = height * s,
// cols = width * s; tiles are aligned to pixels. Equirectangular cameras get an exact spherical grid;
// other models a table from CameraModel::Unproject (computed on a lattice every 4 rays and interpolated
// in between, well below 0.01 px for smooth lens models).
struct CameraRays {
  CameraRays(const CameraModel& camera, int supersample);
  int width, height, supersample;
  RayGrid grid;
};

}  // namespace fusecal::sim
