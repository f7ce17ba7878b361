// Camera image rendering: a noiseless float render (the expensive, geometric part) and the per-frame
// exposure gain and noise on top of it (cheap). Splitting the two lets the simulation render a still
// pose once and draw fresh noise for every frame taken there; the bytes are the same as rendering each
// frame from scratch.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "runtime/sim/simulator/ray_grid.hpp"
#include "runtime/sim/simulator/scenario.hpp"
#include "runtime/sim/simulator/scene.hpp"
#include "stages/foundation/camera_model.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal::sim {

// Noiseless image, CV_32F (grey) or CV_32FC3 (BGR), values 0..255: the mean of the supersampled rays of
// each pixel. Deterministic, whatever the thread count.
cv::Mat RenderClean(const Scene& scene, const CameraRays& rays, const Isometry3& T_world_camera, bool color,
                    int threads = 0);

// 8-bit image (CV_8U or CV_8UC3): round(gain * clean + sigma * n) with n ~ N(0, 1) per pixel and channel,
// drawn from `seed` (quantised Gaussian, see Rng::FastGaussian), saturated to 0..255.
cv::Mat ApplyImageNoise(const cv::Mat& clean, double gain, double sigma, uint64_t seed, int threads = 0);

// Both steps, for one image; builds the camera's rays (cache a CameraRays and call RenderClean for
// many frames).
cv::Mat RenderImage(const Scene& scene, const CameraModel& camera, const Isometry3& T_world_camera,
                    const RenderOptions& options, uint64_t seed);

// The same camera at a fraction of the resolution (for cheap renders that are resized back up with
// cv::resize: pixel centres map as (u + 0.5) * scale - 0.5).
CameraParams ScaleCamera(const CameraParams& params, double scale);

// World point seen at `pixel` (nullopt-like: false when the ray hits nothing).
bool CastPixel(const Scene& scene, const CameraModel& camera, const Isometry3& T_world_camera,
               const Eigen::Vector2d& pixel, Eigen::Vector3d* p_world);

}  // namespace fusecal::sim
