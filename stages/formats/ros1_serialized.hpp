// ROS 1 messages that fusecal reads from their serialized bytes, as a ROS 1 bag stores them, for types
// that no Debian package generates C++ for: little-endian, no alignment, strings and variable arrays as
// a uint32 length and the elements, fixed arrays as the elements (the ROS 1 wiki's "msg serialization").
// std_msgs/Header is uint32 seq, time (uint32 sec, uint32 nsec), string frame_id.
//
// Throws std::runtime_error naming the type, the field and its byte offset when the bytes do not hold
// the message; every length is checked against the bytes that remain before anything is allocated.
// Bytes after the message are ignored.
#pragma once

#include <cstddef>
#include <cstdint>

#include "stages/formats/ros_sensor_messages.hpp"

namespace fusecal {

// livox_ros_driver2/CustomMsg and livox_ros_driver/CustomMsg (the same fields).
RosLivoxCustomMsg DecodeRos1LivoxCustomMsg(const uint8_t* data, size_t size);

}  // namespace fusecal
