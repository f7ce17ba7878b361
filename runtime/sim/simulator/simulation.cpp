#include "runtime/sim/simulator/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "runtime/sim/simulator/random.hpp"
#include "runtime/sim/simulator/render.hpp"

namespace fusecal::sim {

namespace {

constexpr uint64_t kCameraStream = 1, kLidarStream = 2, kRigCameraStream = 3;

// Sensor tag of camera i's frame seeds: camera 0 keeps the one of a one-camera rig.
uint64_t CameraStream(int i) { return i == 0 ? kCameraStream : MixSeed(kRigCameraStream, static_cast<uint64_t>(i)); }

// Sample times phase + k / rate (microseconds after the start) inside [0, duration].
std::vector<int64_t> SampleTimes(double phase_s, double rate_hz, double duration_s) {
  std::vector<int64_t> out;
  for (int64_t k = 0;; ++k) {
    const double t = phase_s + k / rate_hz;
    if (t > duration_s) break;
    out.push_back(std::llround(t * 1e6));
  }
  return out;
}

// Camera i's extrinsic at the start, then one per change of it, from the middle of the motion after its
// stop.
std::vector<ExtrinsicEpoch> Extrinsics(const Scenario& scenario, const Trajectory& trajectory, int i) {
  std::vector<ExtrinsicEpoch> out{{scenario.start_utime, scenario.cameras[i].T_camera_lidar, 0, i}};
  for (const ExtrinsicChange& c : scenario.extrinsic_changes) {
    if (c.camera < 0 || c.camera >= static_cast<int>(scenario.cameras.size()))
      throw std::invalid_argument("Simulation: extrinsic change of camera " + std::to_string(c.camera) + " of " +
                                  std::to_string(scenario.cameras.size()));
    if (c.camera != i) continue;
    if (c.after_stop < 1 || c.after_stop > static_cast<int>(trajectory.motions().size()) ||
        c.after_stop <= out.back().after_stop)
      throw std::invalid_argument("Simulation: extrinsic change after stop " + std::to_string(c.after_stop) +
                                  " has no motion after it, or is out of order");
    const Motion& m = trajectory.motions()[c.after_stop - 1];
    const int64_t from = scenario.start_utime + std::llround(0.5 * (m.t_from + m.t_to) * 1e6);
    out.push_back({from, out.back().T_camera_lidar * c.delta, c.after_stop, i});
  }
  return out;
}

}  // namespace

Simulation::Simulation(const Scenario& scenario, const std::string& texture_dir, int threads)
    : scenario_(scenario),
      scene_(BuildScene(scenario, texture_dir)),
      trajectory_(BuildTrajectory(scenario)),
      lidar_(scenario.lidar),
      threads_(threads) {
  if (scenario_.cameras.empty()) throw std::invalid_argument("Simulation: the scenario has no camera");
  const double duration = trajectory_.duration();
  cameras_.resize(scenario_.cameras.size());
  for (size_t i = 0; i < cameras_.size(); ++i) {
    Camera& c = cameras_[i];
    const CameraSettings& settings = scenario_.cameras[i].settings;
    c.stream = CameraStream(static_cast<int>(i));
    c.model = MakeCameraModel(settings.params);
    c.times = SampleTimes(settings.phase_s, settings.rate_hz, duration);
    c.extrinsics = Extrinsics(scenario_, trajectory_, static_cast<int>(i));
    for (size_t k = 0; k < c.times.size(); ++k)
      schedule_.push_back({c.times[k], Event::Type::kCamera, static_cast<int>(i), static_cast<int>(k)});
  }
  lidar_times_ = SampleTimes(scenario_.lidar.phase_s, scenario_.lidar.rate_hz, duration);
  for (size_t k = 0; k < lidar_times_.size(); ++k)
    schedule_.push_back({lidar_times_[k], Event::Type::kLidar, 0, static_cast<int>(k)});
  std::sort(schedule_.begin(), schedule_.end(), [](const Scheduled& a, const Scheduled& b) {
    if (a.utime != b.utime) return a.utime < b.utime;
    if (a.type != b.type) return a.type == Event::Type::kCamera;
    if (a.camera != b.camera) return a.camera < b.camera;
    return a.index < b.index;
  });
}

int64_t Simulation::ToUtime(double t) const { return scenario_.start_utime + std::llround(t * 1e6); }
double Simulation::ToSeconds(int64_t utime) const { return (utime - scenario_.start_utime) * 1e-6; }

const Isometry3& Simulation::T_camera_lidar_at(int camera, int64_t utime) const {
  const std::vector<ExtrinsicEpoch>& epochs = extrinsics(camera);
  size_t k = 0;
  while (k + 1 < epochs.size() && epochs[k + 1].from_utime <= utime) ++k;
  return epochs[k].T_camera_lidar;
}

Isometry3 Simulation::T_world_camera(int camera, double t) const {
  return trajectory_.T_world_lidar(t) * T_camera_lidar_at(camera, ToUtime(t)).inverse();
}

std::vector<Station> Simulation::Stations() const {
  std::vector<Station> out;
  for (const auto& s : trajectory_.stills()) {
    const int64_t from = ToUtime(s.t_from);
    std::vector<Isometry3> T_world_cameras;
    for (int i = 0; i < num_cameras(); ++i)
      T_world_cameras.push_back(s.T_world_lidar * T_camera_lidar_at(i, from).inverse());
    out.push_back({s.station_id, from, ToUtime(s.t_to), s.T_world_lidar, T_world_cameras.front(), T_world_cameras});
  }
  return out;
}

const CameraRays& Simulation::Rays(int camera, bool still) {
  Camera& c = cameras_[camera];
  const CameraSettings& settings = scenario_.cameras[camera].settings;
  if (still) {
    if (!c.still_rays) c.still_rays = std::make_unique<CameraRays>(*c.model, settings.supersample);
    return *c.still_rays;
  }
  if (!c.moving_rays) {
    c.moving_model = MakeCameraModel(ScaleCamera(settings.params, settings.moving_scale));
    c.moving_rays = std::make_unique<CameraRays>(*c.moving_model, settings.moving_supersample);
  }
  return *c.moving_rays;
}

CameraFrame Simulation::RenderCameraFrame(int camera, int index) {
  Camera& c = cameras_.at(camera);
  const CameraSettings& settings = scenario_.cameras[camera].settings;
  CameraFrame f;
  f.camera = camera;
  f.index = index;
  f.utime = scenario_.start_utime + c.times.at(index);
  const double t = c.times[index] * 1e-6;
  f.T_world_camera = trajectory_.T_world_lidar(t) * T_camera_lidar_at(camera, f.utime).inverse();
  f.station_id = trajectory_.StillStation(t, t);
  const uint64_t seed = MixSeed(MixSeed(scenario_.seed, c.stream), static_cast<uint64_t>(index));
  cv::Mat clean;
  if (f.station_id >= 0) {
    if (c.cached_image_station != f.station_id) {
      c.cached_image = RenderClean(scene_, Rays(camera, true), f.T_world_camera, settings.color, threads_);
      c.cached_image_station = f.station_id;
    }
    clean = c.cached_image;
  } else {
    clean = RenderClean(scene_, Rays(camera, false), f.T_world_camera, settings.color, threads_);
    if (clean.cols != c.model->width() || clean.rows != c.model->height())
      cv::resize(clean, clean, cv::Size(c.model->width(), c.model->height()), 0, 0, cv::INTER_LINEAR);
  }
  Rng rng(MixSeed(seed, 0xE));
  const double gain = std::exp(scenario_.noise.exposure_sigma * rng.Gaussian());
  f.image = ApplyImageNoise(clean, gain, scenario_.noise.image_sigma, seed, threads_);
  return f;
}

LidarFrame Simulation::RenderLidarFrame(int index) {
  LidarFrame f;
  f.index = index;
  f.utime = scenario_.start_utime + lidar_times_.at(index);
  const double t = lidar_times_[index] * 1e-6;
  f.T_world_lidar = trajectory_.T_world_lidar(t);
  const bool distort = scenario_.lidar.motion_distortion;
  f.station_id = trajectory_.StillStation(t, distort ? t + lidar_.SweepDuration() : t);
  const uint64_t seed = MixSeed(MixSeed(scenario_.seed, kLidarStream), static_cast<uint64_t>(index));
  if (f.station_id >= 0 && lidar_.params().Repetitive()) {
    if (cached_scan_station_ != f.station_id) {
      cached_scan_ = lidar_.CastClean(scene_, f.T_world_lidar, threads_);
      cached_scan_station_ = f.station_id;
    }
    f.scan = lidar_.ApplyNoise(cached_scan_, seed, threads_);
  } else if (distort && f.station_id < 0) {
    const auto pose_at = [this, t](double offset) { return trajectory_.T_world_lidar(t + offset); };
    f.scan = lidar_.ApplyNoise(lidar_.CastClean(scene_, pose_at, threads_, index), seed, threads_);
  } else {
    f.scan = lidar_.ApplyNoise(lidar_.CastClean(scene_, f.T_world_lidar, threads_, index), seed, threads_);
  }
  return f;
}

bool Simulation::Next(Event* event) {
  if (next_ >= schedule_.size()) return false;
  const Scheduled& s = schedule_[next_++];
  event->type = s.type;
  event->utime = scenario_.start_utime + s.utime;
  event->camera = CameraFrame();
  event->lidar = LidarFrame();
  if (s.type == Event::Type::kCamera)
    event->camera = RenderCameraFrame(s.camera, s.index);
  else
    event->lidar = RenderLidarFrame(s.index);
  return true;
}

}  // namespace fusecal::sim
