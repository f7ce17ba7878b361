#include "runtime/sim/simulator/render.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "runtime/sim/simulator/parallel.hpp"
#include "runtime/sim/simulator/random.hpp"

namespace fusecal::sim {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Renders one tile (aligned to pixels) into out; C = 1 (grey) or 3 (BGR).
template <int C>
void RenderTile(const Scene& scene, const CameraRays& rays, const RayTile& tile, const Eigen::Matrix3f& R,
                const Eigen::Vector3f& origin, std::vector<Candidate>* candidates, cv::Mat* out) {
  const int s = rays.supersample;
  RayCone cone;
  cone.origin = origin;
  cone.axis = R * tile.axis;
  cone.cos_half = tile.cos_half;
  cone.sin_half = tile.sin_half;
  scene.Cull(cone, kInf, candidates);
  const Candidate* cand = candidates->data();
  const int n = static_cast<int>(candidates->size());
  const float footprint_rad = tile.spacing_rad;  // one sub-sample
  const float norm = 1.0f / (s * s);
  int hint = -1;  // neighbouring rays mostly hit the same primitive
  for (int py = tile.row0 / s; py < tile.row1 / s; ++py) {
    float* row = out->ptr<float>(py);
    for (int px = tile.col0 / s; px < tile.col1 / s; ++px) {
      float acc[3] = {0, 0, 0};
      for (int sy = 0; sy < s; ++sy) {
        for (int sx = 0; sx < s; ++sx) {
          const Eigen::Vector3f d = R * rays.grid.Direction(py * s + sy, px * s + sx);
          Hit hit;
          float v[3];
          if (scene.Intersect(origin, d, cand, n, kInf, &hit, &hint)) {
            if constexpr (C == 1)
              v[0] = scene.ShadeGrey(hit, hit.t * footprint_rad);
            else
              scene.ShadeBgr(hit, hit.t * footprint_rad, v);
          } else {
            if constexpr (C == 1)
              v[0] = scene.SkyGrey(d);
            else
              scene.SkyBgr(d, v);
          }
          for (int c = 0; c < C; ++c) acc[c] += v[c];
        }
      }
      for (int c = 0; c < C; ++c) row[px * C + c] = acc[c] * norm;
    }
  }
}

}  // namespace

cv::Mat RenderClean(const Scene& scene, const CameraRays& rays, const Isometry3& T_world_camera, bool color,
                    int threads) {
  cv::Mat out(rays.height, rays.width, color ? CV_32FC3 : CV_32F);
  const Eigen::Matrix3f R = T_world_camera.linear().cast<float>() * rays.grid.frame();
  const Eigen::Vector3f origin = T_world_camera.translation().cast<float>();
  const auto& tiles = rays.grid.tiles();
  const int n = static_cast<int>(tiles.size());
  std::vector<std::vector<Candidate>> scratch(ResolveThreads(threads));
  ParallelFor(n, threads, 16, [&](int worker, int i) {
    if (color)
      RenderTile<3>(scene, rays, tiles[i], R, origin, &scratch[worker], &out);
    else
      RenderTile<1>(scene, rays, tiles[i], R, origin, &scratch[worker], &out);
  });
  return out;
}

cv::Mat ApplyImageNoise(const cv::Mat& clean, double gain, double sigma, uint64_t seed, int threads) {
  const int channels = clean.channels();
  cv::Mat out(clean.rows, clean.cols, channels == 3 ? CV_8UC3 : CV_8U);
  const float g = static_cast<float>(gain), sg = static_cast<float>(sigma);
  const int width = clean.cols * channels;
  ParallelFor(clean.rows, threads, 32, [&](int, int r) {
    Rng rng(MixSeed(seed, static_cast<uint64_t>(r)));  // one stream per row: independent of threads
    const float* in = clean.ptr<float>(r);
    uint8_t* o = out.ptr<uint8_t>(r);
    for (int i = 0; i < width; ++i) {
      const float v = g * in[i] + (sg > 0.0f ? sg * rng.FastGaussian() : 0.0f);
      o[i] = static_cast<uint8_t>(std::min(255.0f, std::max(0.0f, v)) + 0.5f);  // round half up
    }
  });
  return out;
}

cv::Mat RenderImage(const Scene& scene, const CameraModel& camera, const Isometry3& T_world_camera,
                    const RenderOptions& options, uint64_t seed) {
  const CameraRays rays(camera, options.supersample);
  const cv::Mat clean = RenderClean(scene, rays, T_world_camera, options.color, options.threads);
  return ApplyImageNoise(clean, options.gain, options.noise_sigma, seed, options.threads);
}

CameraParams ScaleCamera(const CameraParams& params, double scale) {
  CameraParams out = params;
  out.width = std::max(1, static_cast<int>(std::lround(params.width * scale)));
  out.height = std::max(1, static_cast<int>(std::lround(params.height * scale)));
  const double sx = static_cast<double>(out.width) / params.width;
  const double sy = static_cast<double>(out.height) / params.height;
  out.fx = params.fx * sx;
  out.fy = params.fy * sy;
  out.cx = (params.cx + 0.5) * sx - 0.5;
  out.cy = (params.cy + 0.5) * sy - 0.5;
  return out;
}

bool CastPixel(const Scene& scene, const CameraModel& camera, const Isometry3& T_world_camera,
               const Eigen::Vector2d& pixel, Eigen::Vector3d* p_world) {
  const Eigen::Vector3d d = T_world_camera.linear() * camera.Unproject(pixel);
  const Eigen::Vector3f o = T_world_camera.translation().cast<float>();
  Hit hit;
  if (!scene.Intersect(o, d.cast<float>().normalized(), kInf, &hit)) return false;
  *p_world = T_world_camera.translation() + d.normalized() * static_cast<double>(hit.t);
  return true;
}

}  // namespace fusecal::sim
