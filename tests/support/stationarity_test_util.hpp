// Helpers shared by the stationarity tests and benchmark: simulated recordings streamed through the
// detector, scored against the simulator's true still intervals.
#pragma once

#include <cstdint>
#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "foundation/point_cloud.hpp"
#include "simulator/lidar.hpp"
#include "simulator/scenario.hpp"
#include "simulator/simulation.hpp"
#include "stationarity/stationarity_detector.hpp"

namespace fusecal::stationarity_test {

inline std::string ScenarioPath(const std::string& name) { return std::string(FUSECAL_SCENARIO_DIR) + "/" + name; }

inline PointCloud ToPointCloud(const sim::SimulatedScan& scan) {
  PointCloud c;
  c.points.reserve(scan.points.size());
  c.intensity.reserve(scan.points.size());
  c.ring.reserve(scan.points.size());
  c.time_offset_s.reserve(scan.points.size());
  for (const auto& p : scan.points) {
    c.points.emplace_back(p.x, p.y, p.z);
    c.intensity.push_back(p.intensity);
    c.ring.push_back(static_cast<int16_t>(p.ring));
    c.time_offset_s.push_back(p.time_offset_us * 1e-6f);
  }
  return c;
}

// One recorded frame of a simulation, kept in memory so several tests can replay it.
struct Frame {
  bool camera = true;
  int64_t utime = 0;
  int station_id = -1;  // simulator truth: the still interval the frame (a scan: its whole sweep) lies in
  cv::Mat image;
  PointCloud cloud;
};

inline std::vector<Frame> RecordSimulation(const sim::Scenario& scenario, std::vector<sim::Station>* truth) {
  sim::Simulation simulation(scenario);
  if (truth) *truth = simulation.Stations();
  std::vector<Frame> frames;
  sim::Event e;
  while (simulation.Next(&e)) {
    Frame f;
    f.camera = e.type == sim::Event::Type::kCamera;
    f.utime = e.utime;
    if (f.camera) {
      f.station_id = e.camera.station_id;
      f.image = e.camera.image;
    } else {
      f.station_id = e.lidar.station_id;
      f.cloud = ToPointCloud(e.lidar.scan);
    }
    frames.push_back(std::move(f));
  }
  return frames;
}

struct EmittedStation {
  DetectedStation station;
  int64_t emitted_at = 0;  // utime of the frame whose arrival emitted it
};

inline std::vector<EmittedStation> Replay(const std::vector<Frame>& frames, StationarityDetector* detector,
                                          bool flush = true) {
  std::vector<EmittedStation> out;
  for (const Frame& f : frames) {
    auto s = f.camera ? detector->AddImage(f.utime, f.image) : detector->AddScan(f.utime, f.cloud);
    for (auto& st : s) out.push_back({std::move(st), f.utime});
  }
  if (flush) {
    const int64_t last = frames.empty() ? 0 : frames.back().utime;
    if (auto st = detector->Flush()) out.push_back({std::move(*st), last});
  }
  return out;
}

// Scores stations against the true still intervals.
struct Score {
  int true_intervals = 0;
  int found = 0;               // intervals with exactly one station inside
  int missed = 0;              // intervals with none
  int duplicates = 0;          // extra stations in an interval
  int during_motion = 0;       // stations whose image or scan was not taken inside a still interval
  double worst_latency_s = 0;  // emission time - (true start + min_still_s), worst over found stations
};

inline Score ScoreStations(const std::vector<EmittedStation>& stations, const std::vector<sim::Station>& truth,
                           const std::map<int64_t, int>& camera_station, const std::map<int64_t, int>& scan_station,
                           double min_still_s) {
  Score score;
  score.true_intervals = static_cast<int>(truth.size());
  std::vector<int> count(truth.size(), 0);
  for (const auto& e : stations) {
    const DetectedStation& s = e.station;
    const auto ci = camera_station.find(s.image_utime), si = scan_station.find(s.scan_utime);
    const int cam_id = ci == camera_station.end() ? -1 : ci->second;
    const int scan_id = si == scan_station.end() ? -1 : si->second;
    if (cam_id < 0 || cam_id != scan_id) {
      ++score.during_motion;
      continue;
    }
    const sim::Station& t = truth.at(cam_id);
    if (s.utime < t.still_from_utime || s.utime > t.still_to_utime) {
      ++score.during_motion;
      continue;
    }
    if (++count[cam_id] == 1) {
      const double latency = (e.emitted_at - t.still_from_utime) * 1e-6 - min_still_s;
      score.worst_latency_s = std::max(score.worst_latency_s, latency);
    }
  }
  for (int c : count) {
    if (c == 0) ++score.missed;
    if (c >= 1) ++score.found;
    if (c > 1) score.duplicates += c - 1;
  }
  return score;
}

inline void TruthMaps(const std::vector<Frame>& frames, std::map<int64_t, int>* camera_station,
                      std::map<int64_t, int>* scan_station) {
  for (const Frame& f : frames) (f.camera ? *camera_station : *scan_station)[f.utime] = f.station_id;
}

}  // namespace fusecal::stationarity_test

namespace fusecal::stationarity_test {

// The tiny scenario (512x256 panorama, 16-beam LiDAR, 5 still intervals of 1 s), recorded once per process.
struct Recording {
  sim::Scenario scenario;
  std::vector<sim::Station> truth;
  std::vector<Frame> frames;
  std::map<int64_t, int> camera_station, scan_station;
};

inline Recording Record(const sim::Scenario& scenario) {
  Recording r;
  r.scenario = scenario;
  r.frames = RecordSimulation(scenario, &r.truth);
  TruthMaps(r.frames, &r.camera_station, &r.scan_station);
  return r;
}

inline const Recording& TinyRecording() {
  static const Recording r = Record(sim::LoadScenario(ScenarioPath("tiny-equirect.yaml")));
  return r;
}

// The tiny scenario with still intervals of 2 s, long enough for the default min_still_s.
inline const Recording& TinyLongStillRecording() {
  static const Recording r = [] {
    sim::Scenario s = sim::LoadScenario(ScenarioPath("tiny-equirect.yaml"));
    s.motions.still_s = 2.0;
    return Record(s);
  }();
  return r;
}

// Settings for the tiny scenario: its still intervals last 1 s, so the frames inside span 0.9 s.
inline StationaritySettings TinySettings() {
  StationaritySettings s;
  s.min_still_s = 0.5;
  return s;
}

}  // namespace fusecal::stationarity_test
