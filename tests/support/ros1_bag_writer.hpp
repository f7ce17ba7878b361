// The plain ROS sensor messages as ROS 1's sensor_msgs (the inverse of FromRos1 in
// runtime/io/importers/ros_messages.hpp), and a recording written as a ROS 1 bag through rosbag_storage.
// Includes ROS 1 headers: only the files that write ROS 1 bags include it.
#pragma once

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>

#include <string>
#include <vector>

#include "tests/support/recorded_bags.hpp"

namespace fusecal::testing {

std_msgs::Header ToRos1(const RosHeader& header);
sensor_msgs::Image ToRos1(const RosImage& msg);
sensor_msgs::CompressedImage ToRos1(const RosCompressedImage& msg);
sensor_msgs::PointCloud2 ToRos1(const RosPointCloud2& msg);
sensor_msgs::CameraInfo ToRos1(const RosCameraInfo& msg);

// Each message at its arrival time (`cdr` and `order` do not apply).
void WriteRos1Bag(const std::string& path, const std::vector<RecordedMessage>& recording);

}  // namespace fusecal::testing
