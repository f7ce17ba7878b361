// fusecal-camera-frontend: on each STATION, the scaleless camera motion to the same previous stations as
// the LiDAR stage (AKAZE + 5-point RANSAC + epipolar refinement), published as CAMERA_MOTION with
// scaled = false. Features of each station are extracted once and kept for the next pairs; the station
// protocol is the skeleton's: node_kit/station_pair_node.hpp.
#pragma once

#include <memory>

#include "runtime/config_reader.hpp"
#include "stages/camera_frontend/relative_pose.hpp"
#include "stages/node_kit/station_pair_node.hpp"

namespace fusecal {

struct CameraFrontendNodeSettings {
  std::string camera;  // its name on a rig of several (its channels: STATION_<camera>, ...); empty: the one camera
  CameraFrontendNodeSettings() { frontend.features.detection_scale = 0.5; }  // live: AKAZE at half size
  int previous_stations = 1;  // must match lidar_icp.previous_stations; in [1, 10]
  CameraFrontendSettings frontend;

  // Empty when usable, else what is wrong: previous_stations, or frontend.Validate()'s message.
  std::string Validate() const;
};

CameraFrontendNodeSettings ReadCameraFrontendNodeSettings(ConfigReader section);

// What the front end keeps of a station: its features and its camera model.
struct StationFeatures {
  ImageFeatures features;
  std::shared_ptr<const CameraModel> camera;
};

class CameraFrontendNode : public StationPairNode<StationFeatures> {
 public:
  explicit CameraFrontendNode(CameraFrontendNodeSettings settings);

 protected:
  StationFeatures Prepare(const station_t& station) override;
  motion_t Pair(int previous_id, const StationFeatures& previous, const station_t& station,
                const StationFeatures& current) override;

 private:
  CameraFrontendNodeSettings settings_;
};

}  // namespace fusecal
