// ROS 1 sensor messages into the plain structs of formats/ros_sensor_messages.hpp, which
// formats/ros_sensor_conversions.hpp turns into fusecal's types. Only ROS-1-specific .cpp files include
// this header: sensor_msgs pulls Boost and is slow to compile.
// Each function takes the message by value so that a caller done with it can move its bytes in.
#pragma once

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>

#include "stages/formats/ros_sensor_messages.hpp"

namespace fusecal {

RosTime FromRos1(const ros::Time& time);
RosImage FromRos1(sensor_msgs::Image msg);
RosCompressedImage FromRos1(sensor_msgs::CompressedImage msg);
RosPointCloud2 FromRos1(sensor_msgs::PointCloud2 msg);
RosCameraInfo FromRos1(sensor_msgs::CameraInfo msg);

}  // namespace fusecal
