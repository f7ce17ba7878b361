// `fusecal simulate --scenario FILE.yaml --out LOG [--seed N] [--stations-only]`: a standard LCM log with
// CAMERA_IMAGE and LIDAR_SCAN streams, CAMERA_INFO and GROUND_TRUTH; with --stations-only, one STATION
// per still interval instead of the streams (for testing stages without the stationarity detector).
// GROUND_TRUTH: one message per extrinsic (more than one when the scenario moves the camera on its
// mount), each written at the utime from which it holds.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>

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

// The truth with the extrinsic that holds from epoch.from_utime.
ground_truth_t MakeGroundTruth(sim::Simulation& sim, const sim::ExtrinsicEpoch& epoch) {
  const int64_t utime = epoch.from_utime;
  ground_truth_t truth{};
  truth.utime = utime;
  truth.source = "simulation: scenario " + sim.scenario().name + ", seed " + std::to_string(sim.scenario().seed);
  if (epoch.after_stop > 0)
    truth.source += ", camera moved on its mount after stop " + std::to_string(epoch.after_stop);
  ToRowMajor(epoch.T_camera_lidar, truth.T_camera_lidar);
  truth.camera = CameraToMsg(sim.camera().params(), utime);
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

// Writes the GROUND_TRUTH messages that hold from `utime` or earlier and are not written yet.
class TruthWriter {
 public:
  TruthWriter(sim::Simulation& sim, LogWriter& writer) : sim_(sim), writer_(writer) {}
  void WriteUpTo(int64_t utime) {
    const auto& epochs = sim_.extrinsics();
    for (; next_ < epochs.size() && epochs[next_].from_utime <= utime; ++next_)
      writer_.WriteMessage(channels::kGroundTruth, epochs[next_].from_utime, MakeGroundTruth(sim_, epochs[next_]));
  }
  void WriteRest() { WriteUpTo(std::numeric_limits<int64_t>::max()); }

 private:
  sim::Simulation& sim_;
  LogWriter& writer_;
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
  writer.WriteMessage(channels::kCameraInfo, t0, CameraToMsg(sim.camera().params(), t0));
  TruthWriter truths(sim, writer);
  truths.WriteUpTo(t0);
  int written = 0;
  if (stations_only) {
    const auto stations = sim.Stations();
    ProgressLine progress("simulating stations");
    for (const auto& s : stations) {
      const auto camera =
          sim.RenderCameraFrame(NearestFrame(sim.camera_times(), t0, s.still_from_utime, s.still_to_utime));
      const auto lidar =
          sim.RenderLidarFrame(NearestFrame(sim.lidar_times(), t0, s.still_from_utime, s.still_to_utime));
      station_t station{};
      station.utime = std::max(camera.utime, lidar.utime);
      station.id = s.id;
      station.still_from_utime = s.still_from_utime;
      station.still_to_utime = s.still_to_utime;
      station.image = MatToImage(camera.image, encoding, camera.utime);
      station.cloud = CloudToMsg(ToCloud(lidar.scan), lidar.utime);
      station.camera = CameraToMsg(sim.camera().params(), camera.utime);
      truths.WriteUpTo(station.utime);
      writer.WriteMessage(channels::kStation, station.utime, station);
      progress(++written, static_cast<int>(stations.size()));
    }
  } else {
    ProgressLine progress("simulating " + std::to_string(sim.num_events()) + " frames");
    sim::Event event;
    while (sim.Next(&event)) {
      truths.WriteUpTo(event.utime);
      if (event.type == sim::Event::Type::kCamera)
        writer.WriteMessage(channels::kCameraImage, event.utime, MatToImage(event.camera.image, encoding, event.utime));
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
            << sim.Stations().size() << " still intervals, " << seconds << " s\n";
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
