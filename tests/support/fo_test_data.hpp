// Data for the fusion odometry tests and benchmark: simulated stations (tools/sim/simulator) and the KITTI raw
// snippet (shared/data), plus error measures.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "foundation/camera_model.hpp"
#include "foundation/point_cloud.hpp"
#include "foundation/se3.hpp"
#include "simulator/scenario.hpp"

namespace fusecal::fo_test {

inline double Deg(double rad) { return rad * 180.0 / M_PI; }
inline double Rad(double deg) { return deg * M_PI / 180.0; }

// One simulated station: a still image, a still scan and the true poses.
struct SimStation {
  int id = -1;
  cv::Mat image;
  PointCloud scan;
  Isometry3 T_world_lidar = Isometry3::Identity();
  Isometry3 T_world_camera = Isometry3::Identity();
};

struct SimData {
  sim::Scenario scenario;
  std::unique_ptr<CameraModel> camera;
  Isometry3 T_camera_lidar = Isometry3::Identity();
  std::vector<SimStation> stations;
  double seconds_render = 0.0;
};

// Renders, for each of the first max_stations stations, the camera frame in the middle of its still
// interval and the first LiDAR scan whose whole sweep lies in it.
SimData SimulateStations(const sim::Scenario& scenario, int max_stations = 100);

// True motions of consecutive stations.
Isometry3 TrueCameraMotion(const SimStation& i, const SimStation& j);  // A = T_ci_cj
Isometry3 TrueLidarMotion(const SimStation& i, const SimStation& j);   // B = T_li_lj

// The extrinsic moved by translation_m along a fixed unit direction and rotated by rotation_deg about a
// fixed unit axis (both chosen once, oblique to every sensor axis).
Isometry3 PerturbExtrinsic(const Isometry3& T_camera_lidar, double translation_m, double rotation_deg);

// Path of a shipped scenario file.
std::string ScenarioPath(const std::string& name);

// --- KITTI raw snippet ---
std::string KittiDir();
bool KittiAvailable();
std::string KittiImagePath(int frame);
std::string KittiScanPath(int frame);

}  // namespace fusecal::fo_test
