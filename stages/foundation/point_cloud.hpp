// A LiDAR scan as the stage cores see it: points in the LiDAR frame plus optional per-point fields
// (each either empty or of the same length as `points`). No PCL, no LCM.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace fusecal {

struct PointCloud {
  std::vector<Eigen::Vector3f> points;
  std::vector<float> intensity;      // as the sensor reports it
  std::vector<int16_t> ring;         // beam index of multi-beam scanners
  std::vector<float> time_offset_s;  // point time minus scan time

  size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool HasIntensity() const { return !intensity.empty(); }
};

}  // namespace fusecal
