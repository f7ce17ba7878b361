// fusecal-camera-frontend: on each STATION, the scaleless camera motion to the same previous stations as
// the LiDAR stage (AKAZE + 5-point RANSAC + epipolar refinement), published as CAMERA_MOTION with
// scaled = false. Features of each station are extracted once and kept for the next pairs.
#pragma once

#include <deque>
#include <map>
#include <memory>

#include "camera_frontend/relative_pose.hpp"
#include "fusecal/motion_t.hpp"
#include "fusecal/station_t.hpp"
#include "runtime/config_reader.hpp"
#include "runtime/stage_main.hpp"

namespace fusecal {

struct CameraFrontendNodeSettings {
  int previous_stations = 1;  // must match lidar_icp.previous_stations
  CameraFrontendSettings frontend;
};

CameraFrontendNodeSettings ReadCameraFrontendNodeSettings(ConfigReader section);

class CameraFrontendNode : public StageNode {
 public:
  explicit CameraFrontendNode(CameraFrontendNodeSettings settings) : settings_(std::move(settings)) {}
  void Start(Bus& bus) override;
  StageStatus Status() const override;

 private:
  void OnStation(Bus& bus, const station_t& station);

  CameraFrontendNodeSettings settings_;
  std::unique_ptr<CameraModel> camera_;
  std::deque<std::pair<int, ImageFeatures>> previous_;
  std::vector<Subscription> subscriptions_;
  // Motions published for each station, republished when a station comes again (a restarted stage
  // downstream needs them); the station itself is not processed twice.
  std::map<int, std::vector<motion_t>> published_;
  int stations_ = 0, motions_ = 0, failures_ = 0;
  double busy_s_ = 0;
};

}  // namespace fusecal
