#include "runtime/io/importers/bag_source.hpp"

#include <algorithm>
#include <array>

namespace fusecal {

namespace {

const char* const kSensorKindNames[] = {"Image", "CompressedImage", "PointCloud2", "CameraInfo"};
// Livox's drivers: livox_ros_driver2 (ROS 1 and 2) and the older livox_ros_driver (ROS 1), one layout.
const std::array<const char*, 4> kLivoxCustomMsgTypes = {"livox_ros_driver2/CustomMsg", "livox_ros_driver/CustomMsg",
                                                         "livox_ros_driver2/msg/CustomMsg",
                                                         "livox_ros_driver/msg/CustomMsg"};

}  // namespace

RosMessageKind KindOfType(const std::string& type) {
  for (int i = 0; i < 4; ++i)
    if (type == TypeName(static_cast<RosMessageKind>(i), 1) || type == TypeName(static_cast<RosMessageKind>(i), 2))
      return static_cast<RosMessageKind>(i);
  if (std::find(kLivoxCustomMsgTypes.begin(), kLivoxCustomMsgTypes.end(), type) != kLivoxCustomMsgTypes.end())
    return RosMessageKind::kLivoxCustomMsg;
  return RosMessageKind::kOther;
}

std::string TypeName(RosMessageKind kind, int ros_version) {
  if (kind == RosMessageKind::kOther) return "another type";
  if (kind == RosMessageKind::kLivoxCustomMsg)
    return ros_version == 1 ? "livox_ros_driver2/CustomMsg" : "livox_ros_driver2/msg/CustomMsg";
  const std::string package = ros_version == 1 ? "sensor_msgs/" : "sensor_msgs/msg/";
  return package + kSensorKindNames[static_cast<int>(kind)];
}

}  // namespace fusecal
