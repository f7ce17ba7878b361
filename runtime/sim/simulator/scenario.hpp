// A simulation scenario: scene, sensors, true extrinsic, stop-and-rotate motions, noise.
// Loaded from YAML (configs/scenarios/*.yaml) with every key validated; see LoadScenario.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "stages/foundation/camera_model.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal::sim {

// Image rendering and image noise.
struct RenderOptions {
  int supersample = 2;       // s x s rays per pixel, averaged (anti-aliasing)
  bool color = false;        // 8-bit BGR when true, else 8-bit grey
  double noise_sigma = 0.0;  // Gaussian image noise, grey levels (0..255)
  double gain = 1.0;         // exposure gain applied before the noise
  int threads = 0;           // 0: one per hardware thread; results never depend on it
};

// A LiDAR. Frame: x forward, y left, z up. Spinning models (multibeam, panoramic): rows ("rings") are
// ordered from the top beam (ring 0) down; columns from azimuth +180 deg clockwise (seen from above), as a
// Velodyne spins. Non-repetitive models (rosette, petal; simulator/scan_pattern.hpp): rows are the laser
// lines, columns the firing instants, and the directions differ from frame to frame. The sweep of a scan
// starts at its utime and column c fires at c / columns / rate_hz seconds after it.
struct LidarParams {
  // "multibeam" (HDL-64E-like), "panoramic" (dense sphere), "rosette" (Avia-like: forward field of view,
  // Risley prisms) or "petal" (Mid-360-like: 360 deg azimuth, elevation_deg, swinging lines).
  std::string model = "multibeam";
  int beams = 64;                                     // rows: beams, elevation steps (panoramic) or laser lines
  double point_rate_hz = 240000.0;                    // rosette, petal: points per second over all lines
  std::vector<double> field_of_view_deg{70.4, 77.2};  // rosette: horizontal, vertical (an ellipse)
  double elevation_max_deg = 2.0;                     // top beam
  double elevation_min_deg = -24.8;                   // bottom beam; beams are spaced evenly in between
  std::vector<double> elevations_deg;                 // optional explicit list (one per beam), overrides the above
  double azimuth_resolution_deg = 0.18;               // -> columns = round(360 / resolution)
  double min_range_m = 0.9;
  double max_range_m = 120.0;
  double rate_hz = 10.0;
  double phase_s = 0.047;             // time of the first scan after the start
  double beam_divergence_mrad = 2.0;  // footprint used to filter the texture for intensity
  bool motion_distortion = true;      // each column is taken at the pose of its own firing time
  double range_sigma_m = 0.01;        // Gaussian range noise
  double dropout = 0.0;               // probability that a return is lost
  double intensity_sigma = 0.0;       // Gaussian intensity noise (intensity is in 0..1)

  // Elevation of every beam, radians, top first.
  std::vector<double> ElevationsRad() const;
  int Columns() const;
  bool Repetitive() const { return model == "multibeam" || model == "panoramic"; }
};

struct CameraSettings {
  CameraParams params;
  double rate_hz = 10.0;
  double phase_s = 0.013;      // time of the first image after the start
  int supersample = 2;         // for images taken while still (rendered once per station)
  int moving_supersample = 1;  // for images taken while moving
  double moving_scale = 0.5;   // images taken while moving are rendered at this fraction of the
                               // resolution and upsampled (cheap, and blurred as by motion)
  bool color = false;
};

struct MotionParams {
  int horizontal = 5;              // turns about the vertical axis
  int vertical = 5;                // tilts about a horizontal axis
  double rotation_min_deg = 10.0;  // horizontal: |yaw| per motion
  double rotation_max_deg = 25.0;
  double tilt_min_deg = 8.0;  // vertical: |change of tilt| per motion
  double tilt_max_deg = 16.0;
  double still_s = 3.0;     // standing still before, between and after the motions
  double move_min_s = 2.0;  // duration of a motion (uniform in [min, max])
  double move_max_s = 3.0;
  double translation_m = 0.2;                       // extra horizontal translation per horizontal motion, at most
  double max_drift_m = 0.6;                         // the rig stays this close to its start position
  Eigen::Vector3d yaw_pivot_m{-0.35, 0.05, -0.2};   // pivot of the turns, in the LiDAR frame
  Eigen::Vector3d tilt_pivot_m{-0.25, 0.0, -0.45};  // pivot of the tilts, in the LiDAR frame
  std::string tilt_axis = "pitch";                  // "pitch" (about LiDAR y), "roll" (about x), "alternate"
  std::string order = "alternate";                  // "alternate" (H V H V ...) or "grouped" (all H, then all V)
};

struct NoiseParams {
  double image_sigma = 2.0;     // grey levels
  double exposure_sigma = 0.0;  // per-frame gain = exp(sigma * N(0, 1))
};

// A camera moved on its mount during a session: from the middle of the motion after stop after_stop
// (stops counted from 1) its extrinsic is the previous one times delta, delta in the LiDAR frame.
struct ExtrinsicChange {
  int after_stop = 1;
  Isometry3 delta = Isometry3::Identity();
  int camera = 0;  // which camera moved: an index into Scenario::cameras
};

// A camera of the rig: its name (empty for the one camera of a scenario with a `camera:` section; else
// 1-32 characters of [A-Za-z0-9_], starting with a letter: its channels end in _<name>), its settings
// and its true extrinsic at the start.
struct RigCamera {
  std::string name;
  CameraSettings settings;
  Isometry3 T_camera_lidar = Isometry3::Identity();
};

struct Scenario {
  std::string name;  // file stem, for messages
  uint64_t seed = 1;
  std::string scene = "indoor";  // "indoor" or "outdoor"
  int64_t start_utime = 1700000000000000;
  std::vector<RigCamera> cameras{RigCamera{}};  // one at least; `camera:` gives one with no name
  LidarParams lidar;
  std::vector<ExtrinsicChange> extrinsic_changes;  // each camera's in order of after_stop, one per stop at most
  Eigen::Vector3d rig_position_m{0.4, 0.3, 1.5};   // LiDAR origin at the start, world frame (z up)
  double rig_yaw_deg = 10.0;
  MotionParams motions;
  NoiseParams noise;

  // The first camera (the only one of a one-camera rig).
  CameraSettings& camera() { return cameras.front().settings; }
  const CameraSettings& camera() const { return cameras.front().settings; }
  Isometry3& T_camera_lidar() { return cameras.front().T_camera_lidar; }  // at the start
  const Isometry3& T_camera_lidar() const { return cameras.front().T_camera_lidar; }
  // Index of the camera called `name` in cameras, or -1.
  int CameraIndex(const std::string& name) const;
};

// Loads and validates a scenario file. Throws fusecal::ConfigError naming the offending key.
Scenario LoadScenario(const std::string& path);
Scenario ParseScenario(const std::string& yaml_text);  // same, from a string (tests)

// Path of the shipped scenario directory (configs/scenarios in the source tree).
std::string DefaultScenarioDir();

}  // namespace fusecal::sim
