// Benchmark of the stationarity detector (not a test):
//  - counts: stations found vs true still intervals over the default scenario and two other seeds;
//  - latency: emission time - (true start of the still interval + min_still_s), budget 0.5 s;
//  - throughput on one core: time per AddImage (2048x1024) and per AddScan (~127k points) against the
//    100 ms budget of a 10 Hz rig.
// Usage: bench_stationarity [--scenario FILE] [--seeds N,N,...] [--trace]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <opencv2/core.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "runtime/sim/fixtures/stationarity_test_util.hpp"

using namespace fusecal;
using namespace fusecal::fixtures;

namespace {

struct Timing {
  std::vector<double> ms;
  void Add(double v) { ms.push_back(v); }
  double Quantile(double q) const {
    if (ms.empty()) return 0;
    std::vector<double> v = ms;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5))];
  }
  double Mean() const {
    double s = 0;
    for (double v : ms) s += v;
    return ms.empty() ? 0 : s / ms.size();
  }
};

struct RunResult {
  Score score;
  int stations = 0;
  Timing image, scan;
  int width = 0, height = 0;
  size_t points = 0;
};

RunResult RunScenario(const sim::Scenario& scenario, const StationaritySettings& settings, bool trace) {
  RunResult r;
  sim::Simulation simulation(scenario);
  const std::vector<sim::Station> truth = simulation.Stations();
  StationarityDetector detector(settings);
  std::map<int64_t, int> camera_station, scan_station;
  std::vector<EmittedStation> emitted;
  sim::Event e;
  using Clock = std::chrono::steady_clock;
  while (simulation.Next(&e)) {
    std::vector<DetectedStation> out;
    const auto t0 = Clock::now();
    if (e.type == sim::Event::Type::kCamera) {
      out = detector.AddImage(e.utime, e.camera.image);
      r.image.Add(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
      camera_station[e.utime] = e.camera.station_id;
      r.width = e.camera.image.cols;
      r.height = e.camera.image.rows;
    } else {
      const PointCloud cloud = ToPointCloud(e.lidar.scan);
      const auto t1 = Clock::now();
      out = detector.AddScan(e.utime, cloud);
      r.scan.Add(std::chrono::duration<double, std::milli>(Clock::now() - t1).count());
      scan_station[e.utime] = e.lidar.station_id;
      r.points = std::max(r.points, cloud.size());
    }
    if (trace) {
      const StationarityState s = detector.State();
      std::printf("%s t=%7.3f truth=%2d phase=%-8s flow=%.3f drift=%.3f change=%.4f ldrift=%.4f still_for=%.2f %s\n",
                  e.type == sim::Event::Type::kCamera ? "IMG " : "SCAN", simulation.ToSeconds(e.utime),
                  e.type == sim::Event::Type::kCamera ? e.camera.station_id : e.lidar.station_id, ToString(s.phase),
                  s.image_flow_px, s.image_drift_px, s.lidar_change_m, s.lidar_drift_m, s.still_for_s,
                  s.reason.c_str());
    }
    for (auto& st : out) {
      if (trace)
        std::printf("  -> station %d at t=%.3f (image %.3f scan %.3f, still from %.3f)\n", st.id,
                    simulation.ToSeconds(st.utime), simulation.ToSeconds(st.image_utime),
                    simulation.ToSeconds(st.scan_utime), simulation.ToSeconds(st.still_from));
      emitted.push_back({std::move(st), e.utime});
    }
  }
  if (auto st = detector.Flush()) emitted.push_back({std::move(*st), e.utime});
  r.stations = static_cast<int>(emitted.size());
  r.score = ScoreStations(emitted, truth, camera_station, scan_station, settings.min_still_s);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scenario_path = ScenarioPath("indoor-equirect-hdl64.yaml");
  std::vector<uint64_t> extra_seeds = {1001, 2002};
  bool trace = false, seeds_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--trace") {
      trace = true;
    } else if (a == "--scenario" && i + 1 < argc) {
      scenario_path = argv[++i];
    } else if (a == "--seeds" && i + 1 < argc) {
      extra_seeds.clear();
      std::stringstream ss(argv[++i]);
      std::string item;
      while (std::getline(ss, item, ',')) extra_seeds.push_back(std::stoull(item));
      seeds_given = true;
    } else {
      std::fprintf(stderr, "usage: %s [--scenario FILE] [--seeds N,N,...] [--trace]\n", argv[0]);
      return 2;
    }
  }
  cv::setNumThreads(1);  // the detector's budget is one core (the simulator renders with its own threads)
  const StationaritySettings settings;  // defaults
  const sim::Scenario base = sim::LoadScenario(scenario_path);
  std::vector<uint64_t> seeds;
  if (!seeds_given) seeds.push_back(base.seed);
  seeds.insert(seeds.end(), extra_seeds.begin(), extra_seeds.end());

  std::printf("bench_stationarity: %s, default settings (min_still_s %.2f)\n", scenario_path.c_str(),
              settings.min_still_s);
  std::printf("%-6s %-9s %-6s %-8s %-7s %-10s %-13s %-15s\n", "seed", "intervals", "found", "missed", "extra",
              "in motion", "latency max s", "latency margin");
  Timing all_image, all_scan;
  int total_intervals = 0, total_found = 0, total_bad = 0;
  double worst_latency = 0;
  int width = 0, height = 0;
  size_t points = 0;
  for (uint64_t seed : seeds) {
    sim::Scenario scenario = base;
    scenario.seed = seed;
    const RunResult r = RunScenario(scenario, settings, trace);
    const Score& s = r.score;
    std::printf("%-6llu %-9d %-6d %-8d %-7d %-10d %-13.3f %-15.3f\n", static_cast<unsigned long long>(seed),
                s.true_intervals, s.found, s.missed, s.duplicates, s.during_motion, s.worst_latency_s,
                0.5 - s.worst_latency_s);
    total_intervals += s.true_intervals;
    total_found += s.found;
    total_bad += s.missed + s.duplicates + s.during_motion;
    worst_latency = std::max(worst_latency, s.worst_latency_s);
    all_image.ms.insert(all_image.ms.end(), r.image.ms.begin(), r.image.ms.end());
    all_scan.ms.insert(all_scan.ms.end(), r.scan.ms.begin(), r.scan.ms.end());
    width = r.width;
    height = r.height;
    points = std::max(points, r.points);
  }
  std::printf("\ncounts: %d of %d still intervals found, %d missed/duplicate/in-motion stations\n", total_found,
              total_intervals, total_bad);
  std::printf("latency: worst %.3f s after the end of min_still_s; margin %.3f s against 0.5 s\n", worst_latency,
              0.5 - worst_latency);
  std::printf("throughput (one core, %dx%d images, up to %zu-point scans):\n", width, height, points);
  std::printf("  AddImage: mean %.2f ms, p50 %.2f, p95 %.2f, max %.2f  (%zu calls)\n", all_image.Mean(),
              all_image.Quantile(0.5), all_image.Quantile(0.95), all_image.Quantile(1.0), all_image.ms.size());
  std::printf("  AddScan:  mean %.2f ms, p50 %.2f, p95 %.2f, max %.2f  (%zu calls)\n", all_scan.Mean(),
              all_scan.Quantile(0.5), all_scan.Quantile(0.95), all_scan.Quantile(1.0), all_scan.ms.size());
  const double p95_sum = all_image.Quantile(0.95) + all_scan.Quantile(0.95);
  std::printf("  image + scan per 100 ms frame period (p95 each): %.2f ms; margin %.2f ms (%.1fx)\n", p95_sum,
              100.0 - p95_sum, 100.0 / std::max(p95_sum, 1e-9));
  return total_bad == 0 && total_found == total_intervals ? 0 : 1;
}
