#include "runtime/sim/simulator/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "runtime/sim/simulator/random.hpp"
#include "runtime/sim/simulator/render.hpp"

namespace fusecal::sim {

namespace {

constexpr uint64_t kCameraStream = 1, kLidarStream = 2;

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

// The extrinsic at the start, then one per change, from the middle of the motion after its stop.
std::vector<ExtrinsicEpoch> Extrinsics(const Scenario& scenario, const Trajectory& trajectory) {
  std::vector<ExtrinsicEpoch> out{{scenario.start_utime, scenario.T_camera_lidar, 0}};
  for (const ExtrinsicChange& c : scenario.extrinsic_changes) {
    if (c.after_stop < 1 || c.after_stop > static_cast<int>(trajectory.motions().size()) ||
        c.after_stop <= out.back().after_stop)
      throw std::invalid_argument("Simulation: extrinsic change after stop " + std::to_string(c.after_stop) +
                                  " has no motion after it, or is out of order");
    const Motion& m = trajectory.motions()[c.after_stop - 1];
    const int64_t from = scenario.start_utime + std::llround(0.5 * (m.t_from + m.t_to) * 1e6);
    out.push_back({from, out.back().T_camera_lidar * c.delta, c.after_stop});
  }
  return out;
}

}  // namespace

Simulation::Simulation(const Scenario& scenario, const std::string& texture_dir, int threads)
    : scenario_(scenario),
      scene_(BuildScene(scenario, texture_dir)),
      trajectory_(BuildTrajectory(scenario)),
      camera_(MakeCameraModel(scenario.camera.params)),
      lidar_(scenario.lidar),
      threads_(threads) {
  extrinsics_ = Extrinsics(scenario_, trajectory_);
  const double duration = trajectory_.duration();
  camera_times_ = SampleTimes(scenario_.camera.phase_s, scenario_.camera.rate_hz, duration);
  lidar_times_ = SampleTimes(scenario_.lidar.phase_s, scenario_.lidar.rate_hz, duration);
  for (size_t i = 0; i < camera_times_.size(); ++i)
    schedule_.push_back({camera_times_[i], Event::Type::kCamera, static_cast<int>(i)});
  for (size_t i = 0; i < lidar_times_.size(); ++i)
    schedule_.push_back({lidar_times_[i], Event::Type::kLidar, static_cast<int>(i)});
  std::sort(schedule_.begin(), schedule_.end(), [](const Scheduled& a, const Scheduled& b) {
    if (a.utime != b.utime) return a.utime < b.utime;
    if (a.type != b.type) return a.type == Event::Type::kCamera;
    return a.index < b.index;
  });
}

int64_t Simulation::ToUtime(double t) const { return scenario_.start_utime + std::llround(t * 1e6); }
double Simulation::ToSeconds(int64_t utime) const { return (utime - scenario_.start_utime) * 1e-6; }

const Isometry3& Simulation::T_camera_lidar_at(int64_t utime) const {
  size_t k = 0;
  while (k + 1 < extrinsics_.size() && extrinsics_[k + 1].from_utime <= utime) ++k;
  return extrinsics_[k].T_camera_lidar;
}

Isometry3 Simulation::T_world_camera(double t) const {
  return trajectory_.T_world_lidar(t) * T_camera_lidar_at(ToUtime(t)).inverse();
}

std::vector<Station> Simulation::Stations() const {
  std::vector<Station> out;
  for (const auto& s : trajectory_.stills()) {
    const int64_t from = ToUtime(s.t_from);
    out.push_back(
        {s.station_id, from, ToUtime(s.t_to), s.T_world_lidar, s.T_world_lidar * T_camera_lidar_at(from).inverse()});
  }
  return out;
}

const CameraRays& Simulation::Rays(bool still) {
  if (still) {
    if (!still_rays_) still_rays_ = std::make_unique<CameraRays>(*camera_, scenario_.camera.supersample);
    return *still_rays_;
  }
  if (!moving_rays_) {
    moving_camera_ = MakeCameraModel(ScaleCamera(scenario_.camera.params, scenario_.camera.moving_scale));
    moving_rays_ = std::make_unique<CameraRays>(*moving_camera_, scenario_.camera.moving_supersample);
  }
  return *moving_rays_;
}

CameraFrame Simulation::RenderCameraFrame(int index) {
  CameraFrame f;
  f.index = index;
  f.utime = scenario_.start_utime + camera_times_.at(index);
  const double t = camera_times_[index] * 1e-6;
  f.T_world_camera = trajectory_.T_world_lidar(t) * T_camera_lidar_at(f.utime).inverse();
  f.station_id = trajectory_.StillStation(t, t);
  const uint64_t seed = MixSeed(MixSeed(scenario_.seed, kCameraStream), static_cast<uint64_t>(index));
  cv::Mat clean;
  if (f.station_id >= 0) {
    if (cached_image_station_ != f.station_id) {
      cached_image_ = RenderClean(scene_, Rays(true), f.T_world_camera, scenario_.camera.color, threads_);
      cached_image_station_ = f.station_id;
    }
    clean = cached_image_;
  } else {
    clean = RenderClean(scene_, Rays(false), f.T_world_camera, scenario_.camera.color, threads_);
    if (clean.cols != camera_->width() || clean.rows != camera_->height())
      cv::resize(clean, clean, cv::Size(camera_->width(), camera_->height()), 0, 0, cv::INTER_LINEAR);
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
    event->camera = RenderCameraFrame(s.index);
  else
    event->lidar = RenderLidarFrame(s.index);
  return true;
}

}  // namespace fusecal::sim
