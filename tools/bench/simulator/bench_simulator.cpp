// Renders every frame of a scenario (default: the shipped default scenario) and prints the time.
//   bench_simulator [scenario.yaml] [--dump DIR]   (--dump writes the first image of every station)
#include <chrono>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "runtime/sim/simulator/scenario.hpp"
#include "runtime/sim/simulator/simulation.hpp"

int main(int argc, char** argv) {
  using Clock = std::chrono::steady_clock;
  std::string path = fusecal::sim::DefaultScenarioDir() + "/indoor-equirect-hdl64.yaml";
  std::string dump;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--dump" && i + 1 < argc)
      dump = argv[++i];
    else
      path = arg;
  }
  const auto t0 = Clock::now();
  fusecal::sim::Simulation sim(fusecal::sim::LoadScenario(path));
  const auto t1 = Clock::now();
  fusecal::sim::Event event;
  size_t points = 0;
  int images = 0, scans = 0, still_images = 0, still_scans = 0, last_station = -1;
  double camera_s = 0, lidar_s = 0;
  while (true) {
    const auto a = Clock::now();
    if (!sim.Next(&event)) break;
    const double dt = std::chrono::duration<double>(Clock::now() - a).count();
    if (event.type == fusecal::sim::Event::Type::kCamera) {
      ++images;
      camera_s += dt;
      still_images += event.camera.station_id >= 0;
      if (!dump.empty() && event.camera.station_id >= 0 && event.camera.station_id != last_station) {
        last_station = event.camera.station_id;
        cv::imwrite(dump + "/station" + std::to_string(last_station) + ".png", event.camera.image);
      }
    } else {
      ++scans;
      lidar_s += dt;
      still_scans += event.lidar.station_id >= 0;
      points += event.lidar.scan.points.size();
    }
  }
  const auto t2 = Clock::now();
  std::printf("scenario %s: %.1f s of recording, %zu stations\n", path.c_str(), sim.trajectory().duration(),
              sim.Stations().size());
  std::printf("setup (scene, textures, trajectory): %.2f s\n", std::chrono::duration<double>(t1 - t0).count());
  std::printf("camera: %d images (%d still), %.2f s, %.1f ms/image\n", images, still_images, camera_s,
              1e3 * camera_s / std::max(1, images));
  std::printf("lidar:  %d scans (%d still), %.2f s, %.1f ms/scan, %.0f points/scan\n", scans, still_scans, lidar_s,
              1e3 * lidar_s / std::max(1, scans), static_cast<double>(points) / std::max(1, scans));
  std::printf("total render time: %.2f s\n", std::chrono::duration<double>(t2 - t1).count());
  return 0;
}
