// Synthetic motion pairs for tests and benchmarks: a random extrinsic X = T_camera_lidar, random LiDAR
// motions B_i, camera motions A_i = X B_i X^-1, noise on both, optional removal of the camera scale.
// Deterministic for a given seed (std::mt19937).
#pragma once

#include <cstdint>
#include <optional>
#include <random>
#include <vector>

#include "stages/handeye/handeye_types.hpp"

namespace fusecal {

struct SyntheticMotionSettings {
  int num_motions = 10;
  // Rotation axes of the LiDAR motions (LiDAR frame), drawn uniformly from this list; empty: random axes.
  std::vector<Eigen::Vector3d> axes;
  double min_angle_deg = 10.0;  // rotation angle uniform in [min, max], random sign
  double max_angle_deg = 45.0;
  // LiDAR translation: each component uniform in [-max, max]. 0: pure rotations about the LiDAR origin,
  // i.e. all screw axes through one point (one line when there is one axis).
  double max_translation_m = 1.0;
  // Noise on both sensors, per axis: R = R_true Exp(n_rot), t = t_true + n_trans (MotionPair's model).
  double rotation_noise_deg = 0.0;
  double translation_noise_m = 0.0;
  // Normalise the camera translation to unit length after the noise (camera_scaled = false).
  bool scaleless = false;
  // Attach the true noise covariances as cov_A / cov_B (scaled motions).
  bool attach_covariance = false;
  // The extrinsic; random (uniform rotation, translation components in [-0.5, 0.5] m) when not given.
  std::optional<Isometry3> T_camera_lidar;
  std::uint32_t seed = 1;
};

struct SyntheticMotionSet {
  Isometry3 T_camera_lidar = Isometry3::Identity();
  std::vector<MotionPair> pairs;    // station_i = k, station_j = k + 1
  std::vector<Isometry3> A_true;    // noise-free camera motions (metric)
  std::vector<Isometry3> B_true;    // noise-free LiDAR motions
  std::vector<double> true_scales;  // |t_a true|: what SolveScaleless should recover as s_i
};

SyntheticMotionSet GenerateSyntheticMotions(const SyntheticMotionSettings& settings);

// Motion pairs of a rig whose extrinsic changes (a camera moved on its mount): pairs before `change_at`
// hold X, the pair `change_at` spans the change (its camera motion is X B X'^-1), later ones hold
// X' = X delta. change_at < 0: no change.
struct ChangingMotionSet {
  Isometry3 before = Isometry3::Identity(), after = Isometry3::Identity();
  std::vector<MotionPair> pairs;
  int change_at = -1;
};
ChangingMotionSet GenerateChangingMotions(SyntheticMotionSettings settings, int change_at, const Isometry3& delta);

// Uniformly distributed rotation; translation components uniform in [-max_translation_m, max_translation_m].
Isometry3 RandomIsometry(std::mt19937& rng, double max_translation_m);

// Errors of an estimate in the result's perturbation model: R_true = R_est Exp(d_rot), t_true = t_est + d_t.
Vector6 ExtrinsicError(const Isometry3& estimate, const Isometry3& truth);

}  // namespace fusecal
