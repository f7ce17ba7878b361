// fusecal-lidar-icp: on each STATION, registers its scan to the previous station's (and optionally to
// the k previous ones) and publishes LIDAR_MOTION. A failed registration is published as failed with
// its reason, never as a good motion.
#pragma once

#include <deque>
#include <map>

#include "common/point_cloud.hpp"
#include "fusecal/motion_t.hpp"
#include "fusecal/station_t.hpp"
#include "lidar_icp/registration.hpp"
#include "runtime/config_reader.hpp"
#include "runtime/stage_main.hpp"

namespace fusecal {

struct LidarIcpNodeSettings {
  int previous_stations = 1;  // register each station to this many previous ones
  lidar_icp::RegistrationSettings registration;
};

// Reads the `lidar_icp` section (unknown keys rejected).
LidarIcpNodeSettings ReadLidarIcpNodeSettings(ConfigReader section);

class LidarIcpNode : public StageNode {
 public:
  explicit LidarIcpNode(LidarIcpNodeSettings settings) : settings_(std::move(settings)) {}
  void Start(Bus& bus) override;
  StageStatus Status() const override;

 private:
  void OnStation(Bus& bus, const station_t& station);

  LidarIcpNodeSettings settings_;
  std::deque<std::pair<int, PointCloud>> previous_;  // (station id, scan), newest last
  std::vector<Subscription> subscriptions_;
  // Motions published for each station, republished when a station comes again (a restarted stage
  // downstream needs them); the station itself is not processed twice.
  std::map<int, std::vector<motion_t>> published_;
  int stations_ = 0, motions_ = 0, failures_ = 0;
  double busy_s_ = 0;
  std::string state_ = "waiting";
};

}  // namespace fusecal
