// fusecal-lidar-icp: on each STATION, registers its scan to the previous station's (and optionally to
// the k previous ones) and publishes LIDAR_MOTION. A failed registration is published as failed with
// its reason, never as a good motion. The station protocol (once per station, repeats answered from
// cache) is the skeleton's: node_kit/station_pair_node.hpp.
#pragma once

#include "runtime/config_reader.hpp"
#include "stages/foundation/point_cloud.hpp"
#include "stages/lidar_icp/registration.hpp"
#include "stages/node_kit/station_pair_node.hpp"

namespace fusecal {

struct LidarIcpNodeSettings {
  std::string station_camera;  // whose stations it registers (STATION_<camera>): the rig's first camera
  int previous_stations = 1;   // register each station to this many previous ones, in [1, 10]
  lidar_icp::RegistrationSettings registration;

  // Empty when usable, else what is wrong: previous_stations, or registration.Validate()'s message.
  std::string Validate() const;
};

// Reads the `lidar_icp` section (unknown keys rejected; the ranges are those of Validate()).
LidarIcpNodeSettings ReadLidarIcpNodeSettings(ConfigReader section);

class LidarIcpNode : public StationPairNode<PointCloud> {
 public:
  explicit LidarIcpNode(LidarIcpNodeSettings settings);

 protected:
  PointCloud Prepare(const station_t& station) override;
  motion_t Pair(int previous_id, const PointCloud& previous, const station_t& station,
                const PointCloud& current) override;

 private:
  LidarIcpNodeSettings settings_;
};

}  // namespace fusecal
