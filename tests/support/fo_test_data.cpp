#include "support/fo_test_data.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "simulator/simulation.hpp"

namespace fusecal::fo_test {

namespace {

PointCloud ToPointCloud(const sim::SimulatedScan& scan) {
  PointCloud cloud;
  cloud.points.reserve(scan.points.size());
  cloud.intensity.reserve(scan.points.size());
  cloud.ring.reserve(scan.points.size());
  for (const sim::LidarPoint& p : scan.points) {
    cloud.points.emplace_back(p.x, p.y, p.z);
    cloud.intensity.push_back(p.intensity);
    cloud.ring.push_back(static_cast<int16_t>(p.ring));
  }
  return cloud;
}

}  // namespace

SimData SimulateStations(const sim::Scenario& scenario, int max_stations) {
  const auto start = std::chrono::steady_clock::now();
  SimData data;
  data.scenario = scenario;
  sim::Simulation simulation(scenario);
  data.camera = MakeCameraModel(scenario.camera.params);
  data.T_camera_lidar = simulation.T_camera_lidar();
  const int64_t t0 = scenario.start_utime;
  const int64_t sweep_us = static_cast<int64_t>(1e6 / scenario.lidar.rate_hz);
  for (const sim::Station& station : simulation.Stations()) {
    if (static_cast<int>(data.stations.size()) >= max_stations) break;
    std::vector<int> cameras;
    for (int k = 0; k < simulation.num_camera_frames(); ++k) {
      const int64_t t = t0 + simulation.camera_times()[k];
      if (t >= station.still_from_utime && t <= station.still_to_utime) cameras.push_back(k);
    }
    int lidar = -1;
    for (int k = 0; k < simulation.num_lidar_scans() && lidar < 0; ++k) {
      const int64_t t = t0 + simulation.lidar_times()[k];
      if (t >= station.still_from_utime && t + sweep_us <= station.still_to_utime) lidar = k;
    }
    if (cameras.empty() || lidar < 0) continue;
    SimStation s;
    s.id = station.id;
    const sim::CameraFrame frame = simulation.RenderCameraFrame(cameras[cameras.size() / 2]);
    const sim::LidarFrame scan = simulation.RenderLidarFrame(lidar);
    if (frame.station_id != station.id || scan.station_id != station.id) continue;
    s.image = frame.image;
    s.scan = ToPointCloud(scan.scan);
    s.T_world_camera = frame.T_world_camera;
    s.T_world_lidar = scan.T_world_lidar;
    data.stations.push_back(std::move(s));
  }
  data.seconds_render = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return data;
}

Isometry3 TrueCameraMotion(const SimStation& i, const SimStation& j) {
  return i.T_world_camera.inverse() * j.T_world_camera;
}

Isometry3 TrueLidarMotion(const SimStation& i, const SimStation& j) {
  return i.T_world_lidar.inverse() * j.T_world_lidar;
}

Isometry3 PerturbExtrinsic(const Isometry3& T_camera_lidar, double translation_m, double rotation_deg) {
  const Eigen::Vector3d direction = Eigen::Vector3d(0.6, -0.48, 0.64).normalized();
  const Eigen::Vector3d axis = Eigen::Vector3d(-0.36, 0.8, 0.48).normalized();
  Isometry3 delta = MakeIsometry(ExpSO3(Rad(rotation_deg) * axis), translation_m * direction);
  return delta * T_camera_lidar;
}

std::string ScenarioPath(const std::string& name) { return std::string(FUSECAL_SCENARIO_DIR) + "/" + name; }

std::string KittiDir() { return FUSECAL_KITTI_SNIPPET_DIR; }

std::string KittiImagePath(int frame) {
  char name[64];
  std::snprintf(name, sizeof name, "/image_02/data/%010d.png", frame);
  return KittiDir() + name;
}

std::string KittiScanPath(int frame) {
  char name[64];
  std::snprintf(name, sizeof name, "/velodyne_points/data/%010d.bin", frame);
  return KittiDir() + name;
}

bool KittiAvailable() {
  return std::filesystem::exists(KittiImagePath(0)) && std::filesystem::exists(KittiScanPath(0)) &&
         std::filesystem::exists(KittiDir() + "/calib_cam_to_cam.txt");
}

}  // namespace fusecal::fo_test
