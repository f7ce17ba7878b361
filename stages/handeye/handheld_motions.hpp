// Realistic handheld motion pairs for tests and benchmarks: consecutive poses of one smooth trajectory
// that turns about all three axes, as a LiDAR bundle adjustment (metres) and structure from motion
// (camera translations in arbitrary units) give them. Real odometry errs by about 1 deg per motion, not
// the 0.05 deg of the simulator, and a few motions barely turn. Deterministic for a given seed.
#pragma once

#include <cstdint>
#include <vector>

#include "stages/handeye/handeye_types.hpp"

namespace fusecal {

// How the camera translations come: one unknown factor for the whole trajectory (structure from motion,
// SLAM), or an unrelated length per motion (the direction only, as from an essential matrix).
enum class CameraUnits { kGlobalScale, kPerMotion };

struct HandheldMotionSettings {
  int num_motions = 83;  // as many as a public handheld recording has
  // Turn per motion: log-normal about the median, at most max_turn_deg; `small_turns` of the motions,
  // spread over the trajectory, turn only 0.5-1 deg. The axis wanders smoothly over the sphere.
  double median_turn_deg = 9.7;
  double max_turn_deg = 26.0;
  int small_turns = 8;
  double step_m = 0.4;  // walking: LiDAR translation per motion, about this long
  // Per axis and sensor motion: R = R_true Exp(n), t = t_true + n (residual rms about 1.2 deg).
  double rotation_noise_deg = 0.5;
  // Errors of consecutive motions correlate, as poses from one bundle adjustment or structure from motion
  // do: each sensor's error is n_k = rho n_k-1 + sqrt(1 - rho^2) e_k (0.5: about three motions per
  // independent one, as a real handheld recording's residuals show).
  double noise_correlation = 0.5;
  double lidar_translation_noise_m = 0.02;
  double camera_translation_noise_m = 0.02;  // before the camera's units are applied
  CameraUnits camera_units = CameraUnits::kGlobalScale;
  double camera_units_per_m = 3.0;  // kGlobalScale: the trajectory's unknown scale
  std::uint32_t seed = 1;
};

struct HandheldMotionSet {
  Isometry3 T_camera_lidar = Isometry3::Identity();
  std::vector<MotionPair> pairs;  // station_i = k, station_j = k + 1; camera_scaled false
};

HandheldMotionSet GenerateHandheldMotions(const HandheldMotionSettings& settings);

}  // namespace fusecal
