// A whole simulated recording: the time-ordered camera images and LiDAR scans of a scenario, produced
// lazily, plus the ground truth (stations, trajectory, extrinsics). A rig has one camera or several
// (scenario.cameras), each with its own frame times, model and extrinsic; accessors without a camera
// index are about camera 0. With scenario.extrinsic_changes a camera moves on its mount in the middle of
// the motion after each listed stop: its images from that instant on are rendered with its new
// extrinsic; the other cameras and the LiDAR's trajectory stay the same.
//
// Determinism: frame k of a sensor uses the seed MixSeed(MixSeed(scenario.seed, sensor), k), so its bytes
// depend only on the scenario, never on thread count or on which frames were produced before. Camera 0's
// sensor tag is the same whatever the number of cameras (a one-camera scenario's images do not change
// when written as a cameras: list); camera i > 0 has a tag of its own.
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
  Isometry3 T_world_camera;                // camera 0
  std::vector<Isometry3> T_world_cameras;  // every camera, by index ([0] is T_world_camera)
};

// An extrinsic of a camera and the utime from which it holds (until the camera's next one's).
struct ExtrinsicEpoch {
  int64_t from_utime;
  Isometry3 T_camera_lidar;
  int after_stop;  // the change's stop (counted from 1); 0 for the extrinsic at the start
  int camera = 0;  // index into scenario.cameras
};

struct CameraFrame {
  int64_t utime = 0;
  int camera = 0;       // index into scenario.cameras
  int index = 0;        // the camera's own frame count
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

  // The next event in time order (cameras before the LiDAR on equal utime, cameras by index); false
  // after the last.
  bool Next(Event* event);
  void Rewind() { next_ = 0; }
  size_t num_events() const { return schedule_.size(); }
  int num_cameras() const { return static_cast<int>(cameras_.size()); }
  int num_camera_frames(int camera = 0) const { return static_cast<int>(cameras_.at(camera).times.size()); }
  int num_lidar_scans() const { return static_cast<int>(lidar_times_.size()); }
  // Frame times relative to scenario.start_utime, microseconds.
  const std::vector<int64_t>& camera_times(int camera = 0) const { return cameras_.at(camera).times; }
  const std::vector<int64_t>& lidar_times() const { return lidar_times_; }

  // Any frame directly (the same bytes as through Next).
  CameraFrame RenderCameraFrame(int index) { return RenderCameraFrame(0, index); }
  CameraFrame RenderCameraFrame(int camera, int index);
  LidarFrame RenderLidarFrame(int index);

  // Ground truth.
  std::vector<Station> Stations() const;
  // A camera's extrinsic at the start.
  const Isometry3& T_camera_lidar(int camera = 0) const { return extrinsics(camera).front().T_camera_lidar; }
  // A camera's extrinsics in time order, the first from scenario.start_utime, one more per extrinsic
  // change of that camera.
  const std::vector<ExtrinsicEpoch>& extrinsics(int camera = 0) const { return cameras_.at(camera).extrinsics; }
  // The one in force at utime.
  const Isometry3& T_camera_lidar_at(int64_t utime) const { return T_camera_lidar_at(0, utime); }
  const Isometry3& T_camera_lidar_at(int camera, int64_t utime) const;
  // t: seconds since the start.
  Isometry3 T_world_camera(double t) const { return T_world_camera(0, t); }
  Isometry3 T_world_camera(int camera, double t) const;

  const Scenario& scenario() const { return scenario_; }
  const Scene& scene() const { return scene_; }
  const Trajectory& trajectory() const { return trajectory_; }
  const CameraModel& camera(int i = 0) const { return *cameras_.at(i).model; }
  // Empty for the one camera of a scenario with a camera: section.
  const std::string& camera_name(int i = 0) const { return scenario_.cameras.at(i).name; }
  const LidarSensor& lidar() const { return lidar_; }
  int64_t ToUtime(double t) const;
  double ToSeconds(int64_t utime) const;

 private:
  struct Scheduled {
    int64_t utime;
    Event::Type type;
    int camera;  // kCamera
    int index;
  };
  // A camera's model, frame times, extrinsics and caches.
  struct Camera {
    uint64_t stream = 0;  // sensor tag of its frame seeds
    std::unique_ptr<CameraModel> model;
    std::vector<int64_t> times;
    std::vector<ExtrinsicEpoch> extrinsics;
    std::unique_ptr<CameraModel> moving_model;  // model at moving_scale
    std::unique_ptr<CameraRays> still_rays, moving_rays;
    int cached_image_station = -1;
    cv::Mat cached_image;
  };
  const CameraRays& Rays(int camera, bool still);

  Scenario scenario_;
  Scene scene_;
  Trajectory trajectory_;
  LidarSensor lidar_;
  int threads_;
  std::vector<Camera> cameras_;
  std::vector<int64_t> lidar_times_;
  std::vector<Scheduled> schedule_;
  size_t next_ = 0;

  int cached_scan_station_ = -1;
  CleanScan cached_scan_;
};

}  // namespace fusecal::sim
