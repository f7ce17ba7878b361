// Settings of fusecal-ros2-input (section `ros2_input` of the pipeline config): which ROS 2 topics feed
// the pipeline, and how the DDS side is sized.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "runtime/config_reader.hpp"

namespace fusecal {

inline constexpr const char* kPointCloud2Type = "sensor_msgs/msg/PointCloud2";
inline constexpr const char* kLivoxCustomMsgType = "livox_ros_driver2/msg/CustomMsg";  // Livox's own

// One camera's topics.
struct Ros2CameraTopics {
  std::string name;               // the camera's on a rig of several (the config's cameras); empty: the one camera
  std::string image_topic;        // sensor_msgs/Image; ".../compressed": CompressedImage
  std::string camera_info_topic;  // empty: camera_info beside the image topic or above it
  std::string camera_file;        // a camera YAML used instead of CameraInfo (empty: none)

  bool compressed() const;              // the image topic carries CompressedImage
  std::string CameraInfoTopic() const;  // camera_info_topic, or the one derived from the image topic
};

struct Ros2InputSettings {
  int domain = 0;                                 // ROS_DOMAIN_ID
  std::string image_topic = "/camera/image_raw";  // sensor_msgs/Image; ".../compressed": CompressedImage
  std::string cloud_topic = "/lidar/points";      // of cloud_type
  std::string cloud_type = kPointCloud2Type;      // kPointCloud2Type or kLivoxCustomMsgType
  std::string camera_info_topic;                  // empty: camera_info beside the image topic or above it
  std::string camera_file;                        // a camera YAML used instead of CameraInfo (empty: none)
  double topic_timeout_s = 15;                    // a topic silent this long from the start is an error
  double max_message_mb = 10;                     // the largest message expected: the socket receive
                                                  // buffer asked of the kernel holds 6 of them
  int depth = 4;                                  // samples kept per topic between takes
  // A rig of several cameras (the config's cameras): each camera's topics, every camera of the rig once.
  std::vector<Ros2CameraTopics> cameras;
  std::vector<std::string> rig_cameras{""};  // the rig's cameras

  // Empty when usable, else what is wrong.
  std::string Validate() const;
  bool compressed() const;  // the image topic carries CompressedImage
  bool livox() const { return cloud_type == kLivoxCustomMsgType; }
  std::string CameraInfoTopic() const;  // camera_info_topic, or the one derived from the image topic
  // The topics of every camera of the rig, in the rig's order: image_topic, ... for the one camera.
  std::vector<Ros2CameraTopics> CameraTopics() const;
  // Empty when `cameras` names every camera of the rig once and no other, else what is wrong.
  std::string RigProblem() const;
};

Ros2InputSettings ReadRos2InputSettings(ConfigReader section);

// The socket receive buffer for the ROS 2 domain: 6 of the largest messages, at least 16 MiB (Cyclone's
// default of 2 MB loses best-effort 2.5 MB clouds without counting them).
size_t ReceiveBufferBytes(const Ros2InputSettings& settings);

}  // namespace fusecal
