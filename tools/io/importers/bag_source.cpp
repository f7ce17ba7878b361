#include "importers/bag_source.hpp"

namespace fusecal {

namespace {

const char* const kKindNames[] = {"Image", "CompressedImage", "PointCloud2", "CameraInfo"};

}  // namespace

RosMessageKind KindOfType(const std::string& type) {
  for (int i = 0; i < 4; ++i)
    if (type == TypeName(static_cast<RosMessageKind>(i), 1) || type == TypeName(static_cast<RosMessageKind>(i), 2))
      return static_cast<RosMessageKind>(i);
  return RosMessageKind::kOther;
}

std::string TypeName(RosMessageKind kind, int ros_version) {
  const std::string package = ros_version == 1 ? "sensor_msgs/" : "sensor_msgs/msg/";
  return kind == RosMessageKind::kOther ? "another type" : package + kKindNames[static_cast<int>(kind)];
}

}  // namespace fusecal
