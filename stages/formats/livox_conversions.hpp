// Livox's own point cloud message (livox_ros_driver2/CustomMsg, ros_sensor_messages.hpp) into fusecal's
// PointCloud, as ros_sensor_conversions.hpp turns sensor_msgs/PointCloud2 into one: throws
// std::runtime_error saying what is wrong with the message.
#pragma once

#include "stages/formats/ros_sensor_messages.hpp"
#include "stages/foundation/point_cloud.hpp"

namespace fusecal {

// x, y, z; reflectivity as intensity; line as ring; time_offset_s the point's time (timebase +
// offset_time, nanoseconds) minus the header stamp, none when the stamp is zero (the arrival time stands
// in for it). Points with a non-finite or all-zero position are left out and counted in *dropped, as
// for PointCloud2. A point_num that is not the number of points is an error: the message is garbled.
PointCloud LivoxCustomMsgToPointCloud(const RosLivoxCustomMsg& msg, int* dropped = nullptr);

}  // namespace fusecal
