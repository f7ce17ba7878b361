// ROS 2 sensor messages from their serialized form, as rosbag2 stores them and DDS carries them: a
// 4-byte encapsulation header (0x00 0x00 big-endian CDR, 0x00 0x01 little-endian CDR; any other
// encapsulation is refused), then the fields in the order of the .msg definition, each aligned to its
// size (8 for float64) counted from the end of the encapsulation header. Strings are a uint32 length
// (with the NUL) and the bytes, sequences a uint32 count and the elements, fixed arrays the elements.
//
// Each function throws std::runtime_error naming the message type, the field and its byte offset from
// the start of the serialized message when the bytes do not hold the message; every length is checked
// against the bytes that remain before anything is allocated. Bytes after the message are ignored.
#pragma once

#include <cstddef>
#include <cstdint>

#include "stages/formats/ros_sensor_messages.hpp"

namespace fusecal {

RosPointCloud2 DecodeCdrPointCloud2(const uint8_t* data, size_t size);          // sensor_msgs/msg/PointCloud2
RosImage DecodeCdrImage(const uint8_t* data, size_t size);                      // sensor_msgs/msg/Image
RosCompressedImage DecodeCdrCompressedImage(const uint8_t* data, size_t size);  // .../CompressedImage
RosCameraInfo DecodeCdrCameraInfo(const uint8_t* data, size_t size);            // sensor_msgs/msg/CameraInfo
RosLivoxCustomMsg DecodeCdrLivoxCustomMsg(const uint8_t* data, size_t size);    // livox_ros_driver2/msg/CustomMsg

}  // namespace fusecal
