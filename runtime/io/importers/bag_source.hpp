// A ROS bag as `fusecal import rosbag` reads it, whatever its ROS version: its topics with their types, and
// its messages in recording order, each decoded on request into the plain structs of
// formats/ros_sensor_messages.hpp. ROS 1 bags come through rosbag_storage (rosbag1_source.cpp, the only
// place that sees ROS 1 headers), ROS 2 bags through Rosbag2Reader and the CDR decoder
// (rosbag2_source.cpp). rosbag.cpp does the rest once for both.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "stages/formats/ros_sensor_messages.hpp"

namespace fusecal {

// The sensor messages the import reads. ROS 1 names them "sensor_msgs/Image", ROS 2
// "sensor_msgs/msg/Image"; both are recognised. Livox's CustomMsg is recognised from livox_ros_driver2
// and livox_ros_driver, by name (the bag's message definitions are not read).
enum class RosMessageKind { kImage, kCompressedImage, kPointCloud2, kCameraInfo, kLivoxCustomMsg, kOther };
RosMessageKind KindOfType(const std::string& type);
// "sensor_msgs/Image" for ROS 1, "sensor_msgs/msg/Image" for ROS 2 (livox_ros_driver2's for CustomMsg).
std::string TypeName(RosMessageKind kind, int ros_version);

struct BagTopic {
  std::string name;
  std::string type;  // as the bag names it
  uint64_t message_count = 0;
};

// One message, valid during the visit only. Each accessor decodes the message as that type (the caller
// checks type() first) and throws std::runtime_error when its bytes do not hold one.
class BagMessage {
 public:
  virtual ~BagMessage() = default;
  virtual const std::string& topic() const = 0;
  virtual const std::string& type() const = 0;
  virtual int64_t arrival_utime() const = 0;  // when the recorder received it
  virtual RosImage Image() const = 0;
  virtual RosCompressedImage CompressedImage() const = 0;
  virtual RosPointCloud2 PointCloud2() const = 0;
  virtual RosCameraInfo CameraInfo() const = 0;
  virtual RosLivoxCustomMsg LivoxCustomMsg() const = 0;
};

class BagSource {
 public:
  virtual ~BagSource() = default;
  virtual const std::vector<BagTopic>& topics() const = 0;
  virtual int ros_version() const = 0;  // 1 or 2
  // Calls visit for the messages of `topic_names` in recording order until it returns false. Throws
  // std::runtime_error naming the bag when the bag itself cannot be read further.
  virtual void ForEach(const std::set<std::string>& topic_names,
                       const std::function<bool(const BagMessage&)>& visit) = 0;
  // What the reader read around (a recording cut short, say); empty when nothing.
  virtual std::vector<std::string> warnings() const = 0;
};

// Both throw std::runtime_error naming the path when it is not a bag of that kind.
std::unique_ptr<BagSource> OpenRos1Bag(const std::string& path);
std::unique_ptr<BagSource> OpenRos2Bag(const std::string& path);

}  // namespace fusecal
