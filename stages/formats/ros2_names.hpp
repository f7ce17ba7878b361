// ROS 2 names on DDS (the rmw convention): a topic /camera/image_raw is the DDS topic
// rt/camera/image_raw, a type sensor_msgs/msg/Image is sensor_msgs::msg::dds_::Image_.
#pragma once

#include <string>

namespace fusecal {

struct Ros2TopicSeen {
  std::string topic;  // ROS name when it is a ROS 2 topic ("/camera/image_raw"), else the DDS name
  std::string type;   // ROS name when it is a ROS 2 type ("sensor_msgs/msg/Image"), else the DDS name
};

// "/camera/image_raw" or "camera/image_raw" -> "rt/camera/image_raw". Throws std::invalid_argument for
// an empty name or one with characters ROS does not allow (letters, digits, '_' and '/').
std::string RosTopicToDds(const std::string& ros_topic);
// For settings: empty when `topic` is a ROS topic name, else "<key>: <what is wrong>".
std::string RosTopicProblem(const std::string& key, const std::string& topic);
// "rt/camera/image_raw" -> "/camera/image_raw"; any other DDS topic name is returned as it is.
std::string DdsTopicToRos(const std::string& dds_topic);
// "sensor_msgs::msg::dds_::Image_" -> "sensor_msgs/msg/Image"; any other type name as it is.
std::string DdsTypeToRos(const std::string& dds_type);
// "sensor_msgs/msg/Image" -> "sensor_msgs::msg::dds_::Image_".
std::string RosTypeToDds(const std::string& ros_type);

// The ROS 2 domain of a config that names none, as every ROS 2 tool takes it: ROS_DOMAIN_ID (`value`, null
// when unset; empty is 0), else 0. A value that is not an integer in [0, 232] leaves 0 and sets `problem`
// ("domain: ROS_DOMAIN_ID='x' ...").
int Ros2DomainFromEnvironment(const char* value, std::string* problem);

}  // namespace fusecal
