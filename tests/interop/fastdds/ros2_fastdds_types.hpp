// The plain ROS structs of formats/ros_sensor_messages.hpp as fastddsgen's classes of rosidl's IDL, so
// that the peer publishes what the project's DDS-free encoders (formats/ros_sensor_encode.hpp) make.
// The data buffers are moved, not copied: an image or a cloud is several MB.
#pragma once

#include "fastdds_generated/ros2_messages.h"
#include "stages/formats/ros_sensor_messages.hpp"

namespace fusecal::fastdds_peer {

namespace ros_sensor = sensor_msgs::msg::dds_;

ros_sensor::Image_ ToFastDds(RosImage&& in);
ros_sensor::CompressedImage_ ToFastDds(RosCompressedImage&& in);
ros_sensor::PointCloud2_ ToFastDds(RosPointCloud2&& in);
ros_sensor::CameraInfo_ ToFastDds(RosCameraInfo&& in);
livox_ros_driver2::msg::dds_::CustomMsg_ ToFastDds(RosLivoxCustomMsg&& in);

}  // namespace fusecal::fastdds_peer
