#include "stages/formats/ros1_serialized.hpp"

#include <cstring>
#include <stdexcept>
#include <string>

namespace fusecal {

namespace {

// Reads one ROS 1 message front to back; every read names its field.
class Ros1Reader {
 public:
  Ros1Reader(const uint8_t* data, size_t size, const char* type) : data_(data), size_(size), type_(type) {}

  template <typename T>
  T Scalar(const char* field) {
    T value;
    std::memcpy(&value, Take(sizeof(T), field, "(" + std::to_string(sizeof(T)) + " bytes)"), sizeof(T));
    return value;
  }

  std::string String(const char* field) {
    const uint32_t length = Scalar<uint32_t>(field);
    const auto* bytes = reinterpret_cast<const char*>(Take(length, field, "length " + std::to_string(length)));
    return std::string(bytes, length);
  }

  // A variable array's count and its `count` elements of `element_size` bytes, in place.
  const uint8_t* Array(const char* field, size_t element_size, uint32_t* count) {
    *count = Scalar<uint32_t>(field);
    return Take(static_cast<uint64_t>(*count) * element_size, field, "length " + std::to_string(*count));
  }

 private:
  const uint8_t* Take(uint64_t n, const char* field, const std::string& what) {
    if (n > size_ - pos_)
      throw std::runtime_error(std::string(type_) + ": field '" + field + "' " + what + " runs past the end of the " +
                               std::to_string(size_) + "-byte message at offset " + std::to_string(pos_));
    const uint8_t* at = data_ + pos_;
    pos_ += static_cast<size_t>(n);
    return at;
  }

  const uint8_t* data_;
  size_t size_;
  const char* type_;
  size_t pos_ = 0;
};

// CustomPoint: uint32 offset_time, float32 x, y, z, uint8 reflectivity, tag, line.
constexpr size_t kLivoxPointSize = 19;

RosLivoxPoint LoadLivoxPoint(const uint8_t* p) {
  RosLivoxPoint point;
  std::memcpy(&point.offset_time, p, 4);
  std::memcpy(&point.x, p + 4, 4);
  std::memcpy(&point.y, p + 8, 4);
  std::memcpy(&point.z, p + 12, 4);
  point.reflectivity = p[16];
  point.tag = p[17];
  point.line = p[18];
  return point;
}

}  // namespace

RosLivoxCustomMsg DecodeRos1LivoxCustomMsg(const uint8_t* data, size_t size) {
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "ROS 1 messages are little-endian");
  Ros1Reader in(data, size, "livox_ros_driver2/CustomMsg");
  RosLivoxCustomMsg msg;
  in.Scalar<uint32_t>("header.seq");
  msg.header.stamp.sec = in.Scalar<uint32_t>("header.stamp.sec");
  msg.header.stamp.nsec = in.Scalar<uint32_t>("header.stamp.nsec");
  msg.header.frame_id = in.String("header.frame_id");
  msg.timebase = in.Scalar<uint64_t>("timebase");
  msg.point_num = in.Scalar<uint32_t>("point_num");
  msg.lidar_id = in.Scalar<uint8_t>("lidar_id");
  for (uint8_t& reserved : msg.rsvd) reserved = in.Scalar<uint8_t>("rsvd");
  uint32_t count = 0;
  const uint8_t* points = in.Array("points", kLivoxPointSize, &count);
  msg.points.reserve(count);
  for (uint32_t i = 0; i < count; ++i) msg.points.push_back(LoadLivoxPoint(points + size_t{i} * kLivoxPointSize));
  return msg;
}

}  // namespace fusecal
