#include "runtime/sim/simulator/lidar.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "runtime/sim/simulator/parallel.hpp"
#include "runtime/sim/simulator/random.hpp"
#include "runtime/sim/simulator/scan_pattern.hpp"

namespace fusecal::sim {

namespace {

constexpr int kTileBeams = 8;
constexpr int kTileColumns = 32;
constexpr float kInf = std::numeric_limits<float>::infinity();

float RotationAngle(const Eigen::Matrix3f& A, const Eigen::Matrix3f& B) {
  const float c = 0.5f * ((A.transpose() * B).trace() - 1.0f);
  return std::acos(std::clamp(c, -1.0f, 1.0f));
}

}  // namespace

LidarSensor::LidarSensor(const LidarParams& params) : params_(params), columns_(params.Columns()) {
  if (params.ElevationsRad().empty() || !(params.rate_hz > 0) || !(params.azimuth_resolution_deg > 0) ||
      !(params.max_range_m > params.min_range_m) || !(params.point_rate_hz > 0))
    throw std::invalid_argument("LidarParams: need beams, a positive rate and resolution, max > min range");
  if (!params_.Repetitive()) return;
  // Column c looks at azimuth pi - (c + 0.5) * step: from behind the sensor, clockwise seen from above.
  std::vector<double> azimuth(columns_);
  const double step = 2.0 * M_PI / columns_;
  for (int c = 0; c < columns_; ++c) azimuth[c] = M_PI - (c + 0.5) * step;
  grid_ = std::make_shared<RayGrid>(
      RayGrid::Spherical(params_.ElevationsRad(), azimuth, Eigen::Matrix3f::Identity(), kTileBeams, kTileColumns));
}

std::shared_ptr<const RayGrid> LidarSensor::Rays(int frame) const {
  if (params_.Repetitive()) return grid_;
  // Consecutive instants of one line lie close together: tiles of one line and kTileColumns instants.
  return std::make_shared<RayGrid>(
      RayGrid::Table(params_.beams, columns_, PatternDirections(params_, frame), 1, kTileColumns));
}

CleanScan LidarSensor::CastClean(const Scene& scene, const Isometry3& T_world_lidar, int threads, int frame) const {
  return Cast(scene, Rays(frame), {T_world_lidar.linear().cast<float>()}, {T_world_lidar.translation().cast<float>()},
              threads);
}

CleanScan LidarSensor::CastClean(const Scene& scene, const std::function<Isometry3(double)>& T_world_lidar_at,
                                 int threads, int frame) const {
  std::vector<Eigen::Matrix3f> R(columns_);
  std::vector<Eigen::Vector3f> t(columns_);
  for (int c = 0; c < columns_; ++c) {
    const Isometry3 T = T_world_lidar_at(ColumnTime(c));
    R[c] = T.linear().cast<float>();
    t[c] = T.translation().cast<float>();
  }
  return Cast(scene, Rays(frame), R, t, threads);
}

CleanScan LidarSensor::Cast(const Scene& scene, std::shared_ptr<const RayGrid> rays,
                            const std::vector<Eigen::Matrix3f>& R, const std::vector<Eigen::Vector3f>& t,
                            int threads) const {
  const RayGrid& grid = *rays;
  CleanScan out;
  out.rays = std::move(rays);
  out.beams = grid.rows();
  out.columns = columns_;
  out.range.assign(static_cast<size_t>(out.beams) * columns_, kInf);
  out.intensity.assign(out.range.size(), 0.0f);
  const bool single = R.size() == 1;
  const float divergence = static_cast<float>(params_.beam_divergence_mrad * 1e-3);
  const float min_range = static_cast<float>(params_.min_range_m);
  const float max_range = static_cast<float>(params_.max_range_m);
  const auto& tiles = grid.tiles();
  const int n = static_cast<int>(tiles.size());
  std::vector<std::vector<Candidate>> scratch(ResolveThreads(threads));
  ParallelFor(n, threads, 8, [&](int worker, int i) {
    std::vector<Candidate>& candidates = scratch[worker];
    const RayTile& tile = tiles[i];
    const int c0 = single ? 0 : tile.col0;
    // The tile's cone at the pose of its first column, widened by how far the pose moves across it.
    float slack = 0.0f, turn = 0.0f;
    if (!single) {
      for (int c = tile.col0 + 1; c < tile.col1; ++c) {
        slack = std::max(slack, (t[c] - t[c0]).norm());
        turn = std::max(turn, RotationAngle(R[c0], R[c]));
      }
    }
    RayCone cone;
    cone.origin = t[c0];
    cone.axis = R[c0] * tile.axis;
    const float half = std::min(static_cast<float>(M_PI), tile.half_rad + (single ? 0.0f : turn + 1e-3f));
    cone.cos_half = std::cos(half);
    cone.sin_half = std::sin(half);
    cone.slack = slack + 1e-4f;
    scene.Cull(cone, max_range, &candidates);
    int hint = -1;
    for (int c = tile.col0; c < tile.col1; ++c) {
      const Eigen::Matrix3f& Rc = R[single ? 0 : c];
      const Eigen::Vector3f& tc = t[single ? 0 : c];
      for (int b = tile.row0; b < tile.row1; ++b) {
        const Eigen::Vector3f d = Rc * grid.Direction(b, c);
        Hit hit;
        if (!scene.Intersect(tc, d, candidates.data(), static_cast<int>(candidates.size()), max_range, &hit, &hint))
          continue;
        if (hit.t < min_range) continue;
        const size_t k = static_cast<size_t>(c) * out.beams + b;
        out.range[k] = hit.t;
        out.intensity[k] = scene.ShadeGrey(hit, hit.t * divergence) / 255.0f;
      }
    }
  });
  return out;
}

SimulatedScan LidarSensor::ApplyNoise(const CleanScan& clean, uint64_t seed, int threads) const {
  const float sigma = static_cast<float>(params_.range_sigma_m);
  const float isigma = static_cast<float>(params_.intensity_sigma);
  const double dropout = params_.dropout;
  const float min_range = static_cast<float>(params_.min_range_m);
  const float max_range = static_cast<float>(params_.max_range_m);
  std::vector<float> range(clean.range.size()), intensity(clean.range.size());
  // One random stream per column, so columns can be processed in parallel with the same result.
  ParallelFor(clean.columns, threads, 64, [&](int, int c) {
    Rng rng(MixSeed(seed, static_cast<uint64_t>(c)));
    for (int b = 0; b < clean.beams; ++b) {
      const size_t k = static_cast<size_t>(c) * clean.beams + b;
      float r = clean.range[k];
      float v = clean.intensity[k];
      if (std::isfinite(r)) {
        if (dropout > 0.0 && rng.Uniform() < dropout) r = kInf;
        if (sigma > 0.0f) r += sigma * rng.FastGaussian();
        if (isigma > 0.0f) v = std::clamp(v + isigma * rng.FastGaussian(), 0.0f, 1.0f);
        if (!(r >= min_range && r <= max_range)) r = kInf;
      }
      range[k] = r;
      intensity[k] = v;
    }
  });
  SimulatedScan scan;
  scan.points.reserve(range.size());
  for (int c = 0; c < clean.columns; ++c) {
    const auto time_us = static_cast<int32_t>(std::lround(ColumnTime(c) * 1e6));
    for (int b = 0; b < clean.beams; ++b) {
      const size_t k = static_cast<size_t>(c) * clean.beams + b;
      if (!std::isfinite(range[k])) continue;
      const Eigen::Vector3f p = clean.rays->Direction(b, c) * range[k];
      scan.points.push_back({p.x(), p.y(), p.z(), intensity[k], time_us, static_cast<uint16_t>(b)});
    }
  }
  return scan;
}

SimulatedScan ScanLidar(const Scene& scene, const LidarParams& params, const Isometry3& T_world_lidar, uint64_t seed) {
  const LidarSensor sensor(params);
  return sensor.ApplyNoise(sensor.CastClean(scene, T_world_lidar), seed);
}

}  // namespace fusecal::sim
