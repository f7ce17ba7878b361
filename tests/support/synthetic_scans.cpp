#include "support/synthetic_scans.hpp"

#include <cmath>
#include <limits>
#include <random>

namespace fusecal::testing {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kEps = 1e-9;

// Slab test: entry and exit distances of the ray through the box.
bool Slabs(const Box& b, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double* t_in, double* t_out) {
  double lo = -kInf, hi = kInf;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < kEps) {
      if (o[a] < b.lo[a] || o[a] > b.hi[a]) return false;
      continue;
    }
    double t0 = (b.lo[a] - o[a]) / d[a], t1 = (b.hi[a] - o[a]) / d[a];
    if (t0 > t1) std::swap(t0, t1);
    lo = std::max(lo, t0);
    hi = std::min(hi, t1);
  }
  *t_in = lo;
  *t_out = hi;
  return lo <= hi;
}

}  // namespace

double Scene::Raycast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
  double best = kInf;
  double t_in, t_out;
  if (Slabs(room, o, d, &t_in, &t_out) && t_out > kEps) best = t_out;
  for (const Box& b : boxes)
    if (Slabs(b, o, d, &t_in, &t_out) && t_in > kEps) best = std::min(best, t_in);
  for (const Pillar& p : pillars) {
    // |o_xy + t d_xy - c|^2 = r^2, entering root only.
    const Eigen::Vector2d oc = o.head<2>() - p.center;
    const Eigen::Vector2d dx = d.head<2>();
    const double a = dx.squaredNorm();
    if (a < kEps) continue;
    const double b = 2.0 * oc.dot(dx), c = oc.squaredNorm() - p.radius * p.radius;
    const double disc = b * b - 4 * a * c;
    if (disc < 0) continue;
    const double t = (-b - std::sqrt(disc)) / (2 * a);
    if (t > kEps && t < best) {
      const double z = o.z() + t * d.z();
      if (z >= room.lo.z() && z <= room.hi.z()) best = t;
    }
  }
  return best;
}

Scene MakeRoom() {
  Scene s;
  s.room = {{-5.0, -4.0, -1.2}, {7.0, 5.0, 2.0}};
  s.boxes = {
      {{2.0, -3.6, -1.2}, {3.6, -2.6, -0.45}},  // desk
      {{-4.9, 1.0, -1.2}, {-4.3, 3.2, 0.8}},    // cabinet against the wall
      {{4.0, 2.2, -1.2}, {5.1, 3.6, -0.2}},     // crate
      {{5.6, -2.2, -1.2}, {6.9, -1.6, 1.5}},    // shelf
      {{-1.2, 3.2, -1.2}, {-0.9, 5.0, 2.0}},    // partition wall
      {{-3.5, -3.9, 1.4}, {-1.0, -3.0, 2.0}},   // duct under the ceiling
      {{0.5, 2.0, -1.2}, {1.1, 2.6, -0.7}},     // small box
  };
  s.pillars = {{{-2.2, -1.9}, 0.25}, {{3.1, 1.6}, 0.2}, {{-3.0, 2.4}, 0.15}};
  return s;
}

Scene MakeOtherRoom() {
  Scene s;
  s.room = {{-2.5, -3.5, -1.0}, {3.0, 2.0, 1.6}};
  s.boxes = {{{1.5, 0.5, -1.0}, {2.9, 1.9, 0.2}}, {{-2.4, -3.4, -1.0}, {-1.0, -2.8, 1.6}}};
  s.pillars = {{{0.8, -2.0}, 0.3}};
  return s;
}

ScanPattern Hdl64Pattern(int azimuth_steps) {
  ScanPattern p;
  p.azimuth_steps = azimuth_steps;
  for (int i = 0; i < 64; ++i) p.elevations_rad.push_back((2.0 - 26.8 * i / 63.0) * M_PI / 180.0);
  return p;
}

ScanPattern PanoramicPattern(double step_deg) {
  ScanPattern p;
  p.azimuth_steps = static_cast<int>(std::lround(360.0 / step_deg));
  for (double e = -60.0; e <= 90.0 + 1e-9; e += step_deg) p.elevations_rad.push_back(e * M_PI / 180.0);
  return p;
}

PointCloud SimulateScan(const Scene& scene, const Eigen::Isometry3d& T_world_lidar, const ScanPattern& pattern,
                        double range_noise_m, uint32_t seed, double max_range_m) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, range_noise_m);
  PointCloud cloud;
  const Eigen::Matrix3d R = T_world_lidar.linear();
  const Eigen::Vector3d o = T_world_lidar.translation();
  for (int col = 0; col < pattern.azimuth_steps; ++col) {
    const double az = 2.0 * M_PI * col / pattern.azimuth_steps;
    for (size_t row = 0; row < pattern.elevations_rad.size(); ++row) {
      const double el = pattern.elevations_rad[row];
      const Eigen::Vector3d dir_l(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      const double range = scene.Raycast(o, R * dir_l);
      if (!(range < max_range_m)) continue;
      const double measured = range + (range_noise_m > 0 ? noise(rng) : 0.0);
      cloud.points.push_back((measured * dir_l).cast<float>());
      cloud.intensity.push_back(static_cast<float>(row));
      cloud.ring.push_back(static_cast<int16_t>(row));
      cloud.time_offset_s.push_back(static_cast<float>(0.1 * col / pattern.azimuth_steps));
    }
  }
  return cloud;
}

}  // namespace fusecal::testing
