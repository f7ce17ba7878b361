// Serializes the plain ROS sensor messages (formats/ros_sensor_messages.hpp) as ROS 2 writes them to a
// bag or DDS: the 4-byte encapsulation header, then CDR in either byte order (formats/ros_cdr.hpp reads
// them back). For tests, and for the test bags written from them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "stages/formats/ros_sensor_messages.hpp"

namespace fusecal::testing {

enum class CdrByteOrder { kLittle, kBig };

// The primitives, for tests that build a message by hand (a field of the wrong length, say). Alignment
// counts from the end of the encapsulation header, which the constructor writes.
class CdrWriter {
 public:
  explicit CdrWriter(CdrByteOrder order = CdrByteOrder::kLittle);
  void U8(uint8_t value);
  void U32(uint32_t value);
  void U64(uint64_t value);
  void F32(float value);
  void I32(int32_t value) { U32(static_cast<uint32_t>(value)); }
  void F64(double value);
  void String(const std::string& value);           // length with the NUL, bytes, NUL
  void Bytes(const std::vector<uint8_t>& values);  // uint8[]: count, bytes
  void Header(const RosHeader& header);
  const std::vector<uint8_t>& bytes() const { return bytes_; }

 private:
  void Align(size_t n);
  void Put(uint64_t value, size_t n);
  bool big_endian_;
  std::vector<uint8_t> bytes_;
};

std::vector<uint8_t> EncodeCdr(const RosPointCloud2& msg, CdrByteOrder order = CdrByteOrder::kLittle);
std::vector<uint8_t> EncodeCdr(const RosImage& msg, CdrByteOrder order = CdrByteOrder::kLittle);
std::vector<uint8_t> EncodeCdr(const RosCompressedImage& msg, CdrByteOrder order = CdrByteOrder::kLittle);
std::vector<uint8_t> EncodeCdr(const RosCameraInfo& msg, CdrByteOrder order = CdrByteOrder::kLittle);
std::vector<uint8_t> EncodeCdr(const RosLivoxCustomMsg& msg, CdrByteOrder order = CdrByteOrder::kLittle);

}  // namespace fusecal::testing
