// Synthetic LiDAR scans for the lidar_icp tests and benchmark: a small ray caster of indoor scenes
// (the room seen from inside, boxes, vertical pillars) with an HDL-64E-like multi-beam pattern or a
// dense panoramic (terrestrial scanner) pattern, Gaussian range noise.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "foundation/point_cloud.hpp"

namespace fusecal::testing {

struct Box {
  Eigen::Vector3d lo, hi;
};

struct Pillar {  // vertical cylinder from floor to ceiling
  Eigen::Vector2d center;
  double radius;
};

struct Scene {
  Box room;  // seen from inside: walls, floor, ceiling
  std::vector<Box> boxes;
  std::vector<Pillar> pillars;

  // Distance along the unit ray to the first surface; +inf when nothing is hit.
  double Raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;
};

// A 12 x 9 x 3.2 m room with furniture and pillars placed without symmetry; the origin is 1.2 m above
// the floor, at least 1.5 m from any object.
Scene MakeRoom();
// A different, smaller room (unrelated to MakeRoom).
Scene MakeOtherRoom();

struct ScanPattern {
  std::vector<double> elevations_rad;  // one per beam (row)
  int azimuth_steps = 2000;            // per revolution (columns)
};

// 64 beams evenly from +2 to -24.8 deg, 2000 azimuth steps (~128k rays), as the HDL-64E.
ScanPattern Hdl64Pattern(int azimuth_steps = 2000);
// A full panorama: elevations from -60 to +90 deg every step_deg, azimuth every step_deg.
ScanPattern PanoramicPattern(double step_deg = 0.6);

// Scan taken by a LiDAR at pose T_world_lidar (points in the LiDAR frame), with the beam index as ring.
PointCloud SimulateScan(const Scene& scene, const Eigen::Isometry3d& T_world_lidar, const ScanPattern& pattern,
                        double range_noise_m, uint32_t seed, double max_range_m = 120.0);

}  // namespace fusecal::testing
