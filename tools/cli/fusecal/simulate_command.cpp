// `fusecal simulate --scenario FILE.yaml --out LOG [--seed N] [--stations-only]`: a standard LCM log with
// CAMERA_IMAGE and LIDAR_SCAN streams, CAMERA_INFO and GROUND_TRUTH; with --stations-only, one STATION
// per still interval instead of the streams (for testing stages without the stationarity detector).
// GROUND_TRUTH: one message per extrinsic (more than one when the scenario moves the camera on its
// mount), each written at the utime from which it holds.
// A rig of named cameras (scenario cameras:): each camera has its own CAMERA_IMAGE_<name>,
// CAMERA_INFO_<name> and STATION_<name> (the same station ids and cloud, the camera's own image), its
// camera_info_t.name is <name>, and GROUND_TRUTH has one message per camera and extrinsic (its
// camera.name says which). A one-camera scenario's camera has no name and the plain channels.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <numeric>
#include <vector>

#include "commands.hpp"
#include "fusecal/ground_truth_t.hpp"
#include "fusecal/station_t.hpp"
#include "progress.hpp"
#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"
#include "runtime/sim/simulator/simulation.hpp"
#include "stages/formats/conversions.hpp"

namespace fusecal {

namespace {

PointCloud ToCloud(const sim::SimulatedScan& scan) {
  PointCloud cloud;
  cloud.points.reserve(scan.points.size());
  for (const auto& p : scan.points) {
    cloud.points.emplace_back(p.x, p.y, p.z);
    cloud.intensity.push_back(p.intensity);
    cloud.ring.push_back(static_cast<int16_t>(p.ring));
    cloud.time_offset_s.push_back(static_cast<float>(p.time_offset_us * 1e-6));
  }
  return cloud;
}

// Camera i's camera info, named as the camera.
camera_info_t CameraInfo(const sim::Simulation& sim, int i, int64_t utime) {
  camera_info_t info = CameraToMsg(sim.camera(i).params(), utime);
  info.name = sim.camera_name(i);
  return info;
}

// The truth with the extrinsic of camera epoch.camera that holds from epoch.from_utime.
ground_truth_t MakeGroundTruth(sim::Simulation& sim, const sim::ExtrinsicEpoch& epoch) {
  const int64_t utime = epoch.from_utime;
  const std::string& name = sim.camera_name(epoch.camera);
  ground_truth_t truth{};
  truth.utime = utime;
  truth.source = "simulation: scenario " + sim.scenario().name + ", seed " + std::to_string(sim.scenario().seed);
  if (epoch.after_stop > 0)
    truth.source += ", camera " + (name.empty() ? std::string() : name + " ") + "moved on its mount after stop " +
                    std::to_string(epoch.after_stop);
  ToRowMajor(epoch.T_camera_lidar, truth.T_camera_lidar);
  truth.camera = CameraInfo(sim, epoch.camera, utime);
  for (const auto& s : sim.Stations()) {
    truth.station_id.push_back(s.id);
    std::vector<double> m(16);
    ToRowMajor(s.T_world_lidar, m.data());
    truth.T_world_lidar.push_back(m);
    truth.still_from_utime.push_back(s.still_from_utime);
    truth.still_to_utime.push_back(s.still_to_utime);
  }
  truth.num_stations = static_cast<int32_t>(truth.station_id.size());
  return truth;
}

// The frame of `times` (relative µs) nearest to the middle of [from, to] (absolute utime).
int NearestFrame(const std::vector<int64_t>& times, int64_t start, int64_t from, int64_t to) {
  const int64_t middle = (from + to) / 2 - start;
  int best = 0;
  for (size_t i = 0; i < times.size(); ++i)
    if (std::llabs(times[i] - middle) < std::llabs(times[best] - middle)) best = static_cast<int>(i);
  return best;
}

// Writes the GROUND_TRUTH messages that hold from `utime` or earlier and are not written yet: every
// camera's extrinsics, in time order (cameras by index on equal utime).
class TruthWriter {
 public:
  TruthWriter(sim::Simulation& sim, LogWriter& writer) : sim_(sim), writer_(writer) {
    for (int i = 0; i < sim.num_cameras(); ++i)
      epochs_.insert(epochs_.end(), sim.extrinsics(i).begin(), sim.extrinsics(i).end());
    std::stable_sort(epochs_.begin(), epochs_.end(), [](const sim::ExtrinsicEpoch& a, const sim::ExtrinsicEpoch& b) {
      return a.from_utime < b.from_utime;
    });
  }
  void WriteUpTo(int64_t utime) {
    for (; next_ < epochs_.size() && epochs_[next_].from_utime <= utime; ++next_)
      writer_.WriteMessage(channels::kGroundTruth, epochs_[next_].from_utime, MakeGroundTruth(sim_, epochs_[next_]));
  }
  void WriteRest() { WriteUpTo(std::numeric_limits<int64_t>::max()); }

 private:
  sim::Simulation& sim_;
  LogWriter& writer_;
  std::vector<sim::ExtrinsicEpoch> epochs_;
  size_t next_ = 0;
};

void Simulate(const std::string& scenario_path, const std::string& out, std::optional<uint64_t> seed,
              bool stations_only, const std::string& encoding) {
  CheckReplaceableOutput(out);
  sim::Scenario scenario = sim::LoadScenario(scenario_path);
  if (seed) scenario.seed = *seed;
  const auto start = std::chrono::steady_clock::now();
  sim::Simulation sim(scenario);
  const std::string partial = out + ".partial";
  LogWriter writer(partial);
  const int64_t t0 = scenario.start_utime;
  const int cameras = sim.num_cameras();
  for (int i = 0; i < cameras; ++i)
    writer.WriteMessage(ForCamera(channels::kCameraInfo, sim.camera_name(i)), t0, CameraInfo(sim, i, t0));
  TruthWriter truths(sim, writer);
  truths.WriteUpTo(t0);
  int written = 0;
  if (stations_only) {
    const auto stations = sim.Stations();
    ProgressLine progress("simulating stations");
    for (const auto& s : stations) {
      const auto lidar =
          sim.RenderLidarFrame(NearestFrame(sim.lidar_times(), t0, s.still_from_utime, s.still_to_utime));
      const auto cloud = CloudToMsg(ToCloud(lidar.scan), lidar.utime);
      std::vector<station_t> messages;  // one per camera, each with the same cloud
      for (int i = 0; i < cameras; ++i) {
        const auto camera =
            sim.RenderCameraFrame(i, NearestFrame(sim.camera_times(i), t0, s.still_from_utime, s.still_to_utime));
        station_t station{};
        station.utime = std::max(camera.utime, lidar.utime);
        station.id = s.id;
        station.still_from_utime = s.still_from_utime;
        station.still_to_utime = s.still_to_utime;
        station.image = MatToImage(camera.image, encoding, camera.utime);
        station.cloud = cloud;
        station.camera = CameraInfo(sim, i, camera.utime);
        messages.push_back(std::move(station));
      }
      std::vector<int> order(cameras);  // by utime, cameras by index on equal utime
      std::iota(order.begin(), order.end(), 0);
      std::stable_sort(order.begin(), order.end(),
                       [&messages](int a, int b) { return messages[a].utime < messages[b].utime; });
      for (int i : order) {
        truths.WriteUpTo(messages[i].utime);
        writer.WriteMessage(ForCamera(channels::kStation, sim.camera_name(i)), messages[i].utime, messages[i]);
      }
      progress(++written, static_cast<int>(stations.size()));
    }
  } else {
    ProgressLine progress("simulating " + std::to_string(sim.num_events()) + " frames");
    sim::Event event;
    while (sim.Next(&event)) {
      truths.WriteUpTo(event.utime);
      if (event.type == sim::Event::Type::kCamera)
        writer.WriteMessage(ForCamera(channels::kCameraImage, sim.camera_name(event.camera.camera)), event.utime,
                            MatToImage(event.camera.image, encoding, event.utime));
      else
        writer.WriteMessage(channels::kLidarScan, event.utime, CloudToMsg(ToCloud(event.lidar.scan), event.utime));
      progress(++written, static_cast<int>(sim.num_events()));
    }
  }
  truths.WriteRest();
  writer.Close();
  CheckReplaceableOutput(out);
  std::filesystem::rename(partial, out);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "wrote " << out << ": " << (stations_only ? "stations " : "frames ") << written << ", "
            << sim.Stations().size() << " still intervals, "
            << (cameras > 1 ? std::to_string(cameras) + " cameras, " : std::string()) << seconds << " s\n";
}

}  // namespace

void AddSimulateCommand(CLI::App& app, int* exit_code) {
  auto* cmd = app.add_subcommand("simulate", "render a synthetic LiDAR + camera log with ground truth");
  static std::string scenario, out, encoding = "jpeg";
  static uint64_t seed = 0;
  static bool stations_only = false;
  cmd->add_option("--scenario", scenario, "scenario YAML (configs/scenarios/*.yaml)")->required();
  cmd->add_option("--out", out, "LCM log to write")->required();
  auto* seed_option = cmd->add_option("--seed", seed, "random seed (default: the scenario's)");
  cmd->add_flag("--stations-only", stations_only, "write one STATION per still interval instead of streams");
  cmd->add_option("--image-encoding", encoding, "jpeg (default), png, mono8 or bgr8")
      ->check(CLI::IsMember({"jpeg", "png", "mono8", "bgr8"}));
  cmd->callback([exit_code, seed_option] {
    try {
      Simulate(scenario, out, seed_option->count() ? std::optional<uint64_t>(seed) : std::nullopt, stations_only,
               encoding);
      *exit_code = 0;
    } catch (const std::exception& e) {
      std::remove((out + ".partial").c_str());
      std::cerr << "fusecal simulate: " << e.what() << "\n";
      *exit_code = 1;
    }
  });
}

}  // namespace fusecal
