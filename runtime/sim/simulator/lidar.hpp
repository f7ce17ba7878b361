// LiDAR simulation: cast every row x column ray of a frame (noiseless, CastClean), then draw range noise,
// intensity noise and dropouts per scan (ApplyNoise). See LidarParams for the frame, ring and column
// conventions; spinning models cast the same rays every frame, non-repetitive ones the frame's own
// (simulator/scan_pattern.hpp).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "runtime/sim/simulator/ray_grid.hpp"
#include "runtime/sim/simulator/scenario.hpp"
#include "runtime/sim/simulator/scene.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal::sim {

struct LidarPoint {
  float x, y, z;           // metres, LiDAR frame at the point's own firing time
  float intensity;         // 0..1: grey value of the surface texture / 255 (plus noise, clamped)
  int32_t time_offset_us;  // firing time after the scan's utime (start of the sweep)
  uint16_t ring;           // beam index, 0 = top beam; laser line of non-repetitive models
};

struct SimulatedScan {
  std::vector<LidarPoint> points;  // in firing order: column by column, top beam first
};

// Noiseless returns of all rays; index = column * beams + beam. range = +inf where there is no return.
struct CleanScan {
  int beams = 0, columns = 0;
  std::vector<float> range;
  std::vector<float> intensity;
  std::shared_ptr<const RayGrid> rays;  // the directions cast (row = beam)
};

class LidarSensor {
 public:
  explicit LidarSensor(const LidarParams& params);

  // All columns of frame `frame` at one pose.
  CleanScan CastClean(const Scene& scene, const Isometry3& T_world_lidar, int threads = 0, int frame = 0) const;
  // Column c at T_world_lidar_at(ColumnTime(c)) (motion distortion).
  CleanScan CastClean(const Scene& scene, const std::function<Isometry3(double)>& T_world_lidar_at, int threads = 0,
                      int frame = 0) const;
  // The rays of frame `frame`: the same for every frame of a spinning model.
  std::shared_ptr<const RayGrid> Rays(int frame) const;
  SimulatedScan ApplyNoise(const CleanScan& clean, uint64_t seed, int threads = 0) const;

  // Seconds after the scan's start at which column c fires.
  double ColumnTime(int column) const { return column / (columns_ * params_.rate_hz); }
  double SweepDuration() const { return 1.0 / params_.rate_hz; }
  const LidarParams& params() const { return params_; }
  int beams() const { return params_.Repetitive() ? grid_->rows() : params_.beams; }
  int columns() const { return columns_; }

 private:
  CleanScan Cast(const Scene& scene, std::shared_ptr<const RayGrid> rays, const std::vector<Eigen::Matrix3f>& R,
                 const std::vector<Eigen::Vector3f>& t, int threads) const;

  LidarParams params_;
  int columns_;
  std::shared_ptr<const RayGrid> grid_;  // spinning models: the rays of every frame
};

// One scan at one pose: CastClean + ApplyNoise.
SimulatedScan ScanLidar(const Scene& scene, const LidarParams& params, const Isometry3& T_world_lidar, uint64_t seed);

}  // namespace fusecal::sim
