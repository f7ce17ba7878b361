// A whole simulated recording: the time-ordered camera images and LiDAR scans of a scenario, produced
// lazily, plus the ground truth (stations, trajectory, extrinsics). With scenario.extrinsic_changes the
// camera moves on its mount in the middle of the motion after each listed stop: images from that instant
// on are rendered with the new extrinsic; the LiDAR's trajectory stays the same.
//
// Determinism: frame k of a sensor uses the seed MixSeed(MixSeed(scenario.seed, sensor), k), so its bytes
// depend only on the scenario, never on thread count or on which frames were produced before.
// Speed: while the rig stands still the geometry seen is the same, so the noiseless image and scan of a
// station are rendered once (images with camera.supersample^2 rays per pixel) and each frame there only
// draws its own exposure gain and noise; frames taken while moving are rendered from scratch (images
// at camera.moving_scale of the resolution with camera.moving_supersample, resized back up). A LiDAR
// scan counts as still when its whole sweep is. Non-repetitive LiDARs cast every frame's own rays.
#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "runtime/sim/simulator/lidar.hpp"
#include "runtime/sim/simulator/ray_grid.hpp"
#include "runtime/sim/simulator/scenario.hpp"
#include "runtime/sim/simulator/scene.hpp"
#include "runtime/sim/simulator/trajectory.hpp"
#include "stages/foundation/camera_model.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal::sim {

struct Station {
  int id;
  int64_t still_from_utime, still_to_utime;
  Isometry3 T_world_lidar;
  Isometry3 T_world_camera;
};

// An extrinsic of the recording and the utime from which it holds (until the next one's).
struct ExtrinsicEpoch {
  int64_t from_utime;
  Isometry3 T_camera_lidar;
  int after_stop;  // the change's stop (counted from 1); 0 for the extrinsic at the start
};

struct CameraFrame {
  int64_t utime = 0;
  int index = 0;
  int station_id = -1;  // -1 while moving
  Isometry3 T_world_camera = Isometry3::Identity();
  cv::Mat image;  // CV_8U grey, or CV_8UC3 BGR with camera.color
};

struct LidarFrame {
  int64_t utime = 0;  // start of the sweep
  int index = 0;
  int station_id = -1;                              // -1 unless the whole sweep is still
  Isometry3 T_world_lidar = Isometry3::Identity();  // at the start of the sweep
  SimulatedScan scan;
};

struct Event {
  enum class Type { kCamera, kLidar };
  Type type = Type::kCamera;
  int64_t utime = 0;
  CameraFrame camera;  // filled when type == kCamera
  LidarFrame lidar;    // filled when type == kLidar
};

class Simulation {
 public:
  explicit Simulation(const Scenario& scenario, const std::string& texture_dir = DefaultTextureDir(), int threads = 0);

  // The next event in time order (camera before LiDAR on equal utime); false after the last.
  bool Next(Event* event);
  void Rewind() { next_ = 0; }
  size_t num_events() const { return schedule_.size(); }
  int num_camera_frames() const { return static_cast<int>(camera_times_.size()); }
  int num_lidar_scans() const { return static_cast<int>(lidar_times_.size()); }
  // Frame times relative to scenario.start_utime, microseconds.
  const std::vector<int64_t>& camera_times() const { return camera_times_; }
  const std::vector<int64_t>& lidar_times() const { return lidar_times_; }

  // Any frame directly (the same bytes as through Next).
  CameraFrame RenderCameraFrame(int index);
  LidarFrame RenderLidarFrame(int index);

  // Ground truth.
  std::vector<Station> Stations() const;
  const Isometry3& T_camera_lidar() const { return extrinsics_.front().T_camera_lidar; }  // at the start
  // Every extrinsic in time order, the first from scenario.start_utime, one more per extrinsic change.
  const std::vector<ExtrinsicEpoch>& extrinsics() const { return extrinsics_; }
  const Isometry3& T_camera_lidar_at(int64_t utime) const;  // the one in force at utime
  Isometry3 T_world_camera(double t) const;                 // t: seconds since the start

  const Scenario& scenario() const { return scenario_; }
  const Scene& scene() const { return scene_; }
  const Trajectory& trajectory() const { return trajectory_; }
  const CameraModel& camera() const { return *camera_; }
  const LidarSensor& lidar() const { return lidar_; }
  int64_t ToUtime(double t) const;
  double ToSeconds(int64_t utime) const;

 private:
  struct Scheduled {
    int64_t utime;
    Event::Type type;
    int index;
  };
  const CameraRays& Rays(bool still);

  Scenario scenario_;
  Scene scene_;
  Trajectory trajectory_;
  std::unique_ptr<CameraModel> camera_;
  LidarSensor lidar_;
  int threads_;
  std::vector<ExtrinsicEpoch> extrinsics_;
  std::vector<int64_t> camera_times_, lidar_times_;
  std::vector<Scheduled> schedule_;
  size_t next_ = 0;

  std::unique_ptr<CameraModel> moving_camera_;  // camera_ at camera.moving_scale
  std::unique_ptr<CameraRays> still_rays_, moving_rays_;
  int cached_image_station_ = -1;
  cv::Mat cached_image_;
  int cached_scan_station_ = -1;
  CleanScan cached_scan_;
};

}  // namespace fusecal::sim
