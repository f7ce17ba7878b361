// The ROS sensor messages fusecal reads, as plain structs without ROS: one shape for ROS 1 bags (filled
// from sensor_msgs by runtime/io/importers/ros_messages.hpp), ROS 2 bags and DDS (decoded from CDR by
// ros_cdr.hpp). ros_sensor_conversions.hpp turns them into fusecal's types. Field names and order follow
// the message definitions; the ROS 1 capitals D, K, R, P stand for ROS 2's d, k, r, p.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace fusecal {

// ROS 1 time (uint32 sec, uint32 nsec) and ROS 2's builtin_interfaces/Time (int32 sec, uint32 nanosec).
struct RosTime {
  int64_t sec = 0;
  uint32_t nsec = 0;
  bool IsZero() const { return sec == 0 && nsec == 0; }
};

// std_msgs/Header (ROS 1's seq is left out: nothing uses it and ROS 2 has none).
struct RosHeader {
  RosTime stamp;
  std::string frame_id;
};

struct RosPointField {
  enum : uint8_t { INT8 = 1, UINT8 = 2, INT16 = 3, UINT16 = 4, INT32 = 5, UINT32 = 6, FLOAT32 = 7, FLOAT64 = 8 };
  std::string name;
  uint32_t offset = 0;
  uint8_t datatype = 0;
  uint32_t count = 0;
};

struct RosPointCloud2 {
  RosHeader header;
  uint32_t height = 0;
  uint32_t width = 0;
  std::vector<RosPointField> fields;
  bool is_bigendian = false;
  uint32_t point_step = 0;
  uint32_t row_step = 0;
  std::vector<uint8_t> data;
  bool is_dense = false;
};

// livox_ros_driver2/CustomPoint: a point `offset_time` nanoseconds after its message's timebase.
struct RosLivoxPoint {
  uint32_t offset_time = 0;
  float x = 0, y = 0, z = 0;
  uint8_t reflectivity = 0;
  uint8_t tag = 0;
  uint8_t line = 0;  // the laser
};

// livox_ros_driver2/CustomMsg (livox_ros_driver's has the same fields): one scan of a Livox LiDAR. The
// driver sets the header stamp to timebase, the first point's time in nanoseconds.
struct RosLivoxCustomMsg {
  RosHeader header;
  uint64_t timebase = 0;
  uint32_t point_num = 0;  // the number of points, as the driver counted them
  uint8_t lidar_id = 0;
  std::array<uint8_t, 3> rsvd{};
  std::vector<RosLivoxPoint> points;
};

struct RosImage {
  RosHeader header;
  uint32_t height = 0;
  uint32_t width = 0;
  std::string encoding;
  uint8_t is_bigendian = 0;
  uint32_t step = 0;
  std::vector<uint8_t> data;
};

struct RosCompressedImage {
  RosHeader header;
  std::string format;
  std::vector<uint8_t> data;
};

struct RosRegionOfInterest {
  uint32_t x_offset = 0;
  uint32_t y_offset = 0;
  uint32_t height = 0;
  uint32_t width = 0;
  bool do_rectify = false;
};

struct RosCameraInfo {
  RosHeader header;
  uint32_t height = 0;
  uint32_t width = 0;
  std::string distortion_model;
  std::vector<double> D;
  std::array<double, 9> K{};
  std::array<double, 9> R{};
  std::array<double, 12> P{};
  uint32_t binning_x = 0;
  uint32_t binning_y = 0;
  RosRegionOfInterest roi;
};

}  // namespace fusecal
