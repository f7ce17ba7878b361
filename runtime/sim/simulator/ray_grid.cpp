#include "runtime/sim/simulator/ray_grid.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fusecal::sim {

namespace {
constexpr int kTilePixels = 8;  // camera tiles: 8 x 8 pixels
constexpr int kLattice = 4;     // camera table: Unproject every 4 rays, interpolate in between

float Angle(const Eigen::Vector3f& a, const Eigen::Vector3f& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }
}  // namespace

RayGrid RayGrid::Spherical(const std::vector<double>& elevation_rad, const std::vector<double>& azimuth_rad,
                           const Eigen::Matrix3f& frame, int tile_rows, int tile_cols) {
  RayGrid g;
  g.rows_ = static_cast<int>(elevation_rad.size());
  g.cols_ = static_cast<int>(azimuth_rad.size());
  g.frame_ = frame;
  for (double e : elevation_rad) {
    g.cos_el_.push_back(static_cast<float>(std::cos(e)));
    g.sin_el_.push_back(static_cast<float>(std::sin(e)));
  }
  for (double a : azimuth_rad) {
    g.cos_az_.push_back(static_cast<float>(std::cos(a)));
    g.sin_az_.push_back(static_cast<float>(std::sin(a)));
  }
  g.MakeTiles(tile_rows, tile_cols);
  return g;
}

RayGrid RayGrid::Table(int rows, int cols, std::vector<Eigen::Vector3f> directions, int tile_rows, int tile_cols) {
  if (static_cast<size_t>(rows) * cols != directions.size()) throw std::invalid_argument("RayGrid::Table size");
  RayGrid g;
  g.rows_ = rows;
  g.cols_ = cols;
  g.table_ = std::move(directions);
  g.MakeTiles(tile_rows, tile_cols);
  return g;
}

void RayGrid::MakeTiles(int tile_rows, int tile_cols) {
  tiles_.clear();
  for (int r0 = 0; r0 < rows_; r0 += tile_rows) {
    for (int c0 = 0; c0 < cols_; c0 += tile_cols) {
      RayTile t;
      t.row0 = r0;
      t.row1 = std::min(rows_, r0 + tile_rows);
      t.col0 = c0;
      t.col1 = std::min(cols_, c0 + tile_cols);
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      for (int r = t.row0; r < t.row1; ++r)
        for (int c = t.col0; c < t.col1; ++c) sum += Direction(r, c).cast<double>();
      t.axis = sum.norm() > 1e-9 ? Eigen::Vector3f(sum.normalized().cast<float>()) : Eigen::Vector3f::UnitZ();
      const Eigen::Vector3d axis = t.axis.cast<double>();
      double min_dot = 1.0;
      for (int r = t.row0; r < t.row1; ++r)
        for (int c = t.col0; c < t.col1; ++c)
          min_dot = std::min(min_dot, axis.dot(Direction(r, c).cast<double>().normalized()));
      const float half = static_cast<float>(std::min(M_PI, std::acos(std::max(-1.0, min_dot)) + 1e-4));
      t.half_rad = half;
      t.cos_half = std::cos(half);
      t.sin_half = std::sin(half);
      // Spacing at the tile centre, to neighbours along both directions.
      const int rc = std::min((t.row0 + t.row1) / 2, rows_ - 1), cc = std::min((t.col0 + t.col1) / 2, cols_ - 1);
      const int rn = rc + 1 < rows_ ? rc + 1 : rc - 1, cn = cc + 1 < cols_ ? cc + 1 : cc - 1;
      t.spacing_rad = 0.0f;
      if (rn >= 0) t.spacing_rad = std::max(t.spacing_rad, Angle(Direction(rc, cc), Direction(rn, cc)));
      if (cn >= 0) t.spacing_rad = std::max(t.spacing_rad, Angle(Direction(rc, cc), Direction(rc, cn)));
      tiles_.push_back(t);
    }
  }
}

CameraRays::CameraRays(const CameraModel& camera, int s)
    : width(camera.width()), height(camera.height()), supersample(s) {
  if (s < 1) throw std::invalid_argument("supersample must be >= 1");
  const int rows = height * s, cols = width * s, tile = kTilePixels * s;
  // Pixel coordinate of sub-sample index i (OpenCV convention: pixel centres at integers).
  auto pixel = [s](int i) { return (i + 0.5) / s - 0.5; };
  if (camera.params().model == "equirectangular") {
    // EquirectangularCamera::Unproject in closed form: lon along columns, lat along rows, and
    // camera (x, y, z) = (cos lat sin lon, -sin lat, cos lat cos lon).
    std::vector<double> lat(rows), lon(cols);
    for (int r = 0; r < rows; ++r) lat[r] = M_PI / 2.0 - (pixel(r) + 0.5) / height * M_PI;
    for (int c = 0; c < cols; ++c) lon[c] = (pixel(c) + 0.5) / width * 2.0 * M_PI - M_PI;
    Eigen::Matrix3f frame;
    frame << 0, 1, 0, 0, 0, -1, 1, 0, 0;
    grid = RayGrid::Spherical(lat, lon, frame, tile, tile);
    return;
  }
  // Lattice of exact bearings, then bilinear interpolation and renormalisation.
  const int lr = std::max(2, (rows - 1 + kLattice - 1) / kLattice + 1);
  const int lc = std::max(2, (cols - 1 + kLattice - 1) / kLattice + 1);
  std::vector<Eigen::Vector3f> lattice(static_cast<size_t>(lr) * lc);
  for (int i = 0; i < lr; ++i)
    for (int j = 0; j < lc; ++j) {
      const int r = std::min(i * kLattice, rows - 1), c = std::min(j * kLattice, cols - 1);
      lattice[static_cast<size_t>(i) * lc + j] = camera.Unproject(Eigen::Vector2d(pixel(c), pixel(r))).cast<float>();
    }
  std::vector<Eigen::Vector3f> dirs(static_cast<size_t>(rows) * cols);
  for (int r = 0; r < rows; ++r) {
    const int i = std::min(r / kLattice, lr - 2);
    const int r0 = i * kLattice, r1 = std::min((i + 1) * kLattice, rows - 1);
    const float fr = r1 > r0 ? static_cast<float>(r - r0) / (r1 - r0) : 0.0f;
    for (int c = 0; c < cols; ++c) {
      const int j = std::min(c / kLattice, lc - 2);
      const int c0 = j * kLattice, c1 = std::min((j + 1) * kLattice, cols - 1);
      const float fc = c1 > c0 ? static_cast<float>(c - c0) / (c1 - c0) : 0.0f;
      const auto& a = lattice[static_cast<size_t>(i) * lc + j];
      const auto& b = lattice[static_cast<size_t>(i) * lc + j + 1];
      const auto& d = lattice[static_cast<size_t>(i + 1) * lc + j];
      const auto& e = lattice[static_cast<size_t>(i + 1) * lc + j + 1];
      dirs[static_cast<size_t>(r) * cols + c] =
          ((1 - fr) * ((1 - fc) * a + fc * b) + fr * ((1 - fc) * d + fc * e)).normalized();
    }
  }
  grid = RayGrid::Table(rows, cols, std::move(dirs), tile, tile);
}

}  // namespace fusecal::sim
