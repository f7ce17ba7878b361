#include "stages/formats/ros_cdr.hpp"

#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

namespace fusecal {

namespace {

constexpr size_t kEncapsulationSize = 4;

// Representation identifiers as DDSI-RTPS 2.5 numbers them (and Cyclone DDS and Fast DDS write them),
// for the message that refuses one.
std::string EncapsulationName(unsigned id) {
  static const char* const kNames[] = {"CDR_BE",  "CDR_LE",  "PL_CDR_BE", "PL_CDR_LE", "XML",        "",
                                       "CDR2_BE", "CDR2_LE", "D_CDR2_BE", "D_CDR2_LE", "PL_CDR2_BE", "PL_CDR2_LE"};
  char hex[8];
  std::snprintf(hex, sizeof(hex), "0x%04x", id);
  const bool named = id < sizeof(kNames) / sizeof(kNames[0]) && kNames[id][0] != '\0';
  return std::string(hex) + (named ? std::string(" (") + kNames[id] + ")" : "");
}

// Reads one serialized message front to back. Every read names its field, so that a message that ends
// early or carries a length it cannot hold fails saying where.
class CdrReader {
 public:
  CdrReader(const uint8_t* data, size_t size, const char* type) : data_(data), size_(size), type_(type) {
    if (size < kEncapsulationSize)
      throw std::runtime_error(std::string(type) + ": " + std::to_string(size) + " bytes, shorter than the " +
                               "4-byte encapsulation header");
    const unsigned id = (unsigned{data[0]} << 8) | data[1];
    if (id > 1)
      throw std::runtime_error(std::string(type) + ": encapsulation " + EncapsulationName(id) +
                               " is not supported; plain CDR only (0x0000 CDR_BE, 0x0001 CDR_LE)");
    big_endian_ = id == 0;
    pos_ = kEncapsulationSize;
  }

  uint8_t U8(const std::string& field) { return static_cast<uint8_t>(Primitive(1, field)); }
  bool Bool(const std::string& field) { return U8(field) != 0; }
  uint32_t U32(const std::string& field) { return static_cast<uint32_t>(Primitive(4, field)); }
  int32_t I32(const std::string& field) { return static_cast<int32_t>(U32(field)); }
  uint64_t U64(const std::string& field) { return Primitive(8, field); }
  double F64(const std::string& field) {
    const uint64_t bits = Primitive(8, field);
    double value;
    std::memcpy(&value, &bits, sizeof(value));
    return value;
  }

  std::string String(const std::string& field) {
    const std::vector<uint8_t> bytes = Bytes(field);
    // The length counts the closing NUL; a writer that leaves it out (length 0 for "") is read as well.
    size_t length = bytes.size();
    if (length > 0 && bytes[length - 1] == '\0') --length;
    return std::string(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(length));
  }

  // uint8[] (and a string's bytes): the count, then the bytes.
  std::vector<uint8_t> Bytes(const std::string& field) {
    const uint32_t count = Count(field, 1);
    const uint8_t* begin = data_ + pos_;
    pos_ += count;
    return std::vector<uint8_t>(begin, begin + count);
  }

  // A sequence's count, checked against the remaining bytes: each element takes at least
  // `min_element_size` of them. Aligns to `element_alignment` before the first element.
  uint32_t Count(const std::string& field, size_t min_element_size, size_t element_alignment = 1) {
    Align(4);
    const size_t at = pos_;
    const uint32_t count = U32(field);
    if (count > 0) Align(element_alignment);
    if (pos_ > size_ || static_cast<uint64_t>(count) * min_element_size > size_ - pos_)
      Fail(field, "length " + std::to_string(count), at);
    return count;
  }

  // `count` elements of `element_size` bytes each, `stride` bytes apart (the last one without the padding
  // after it), in place: the caller reads them in byte_order_big_endian(). Follows Count().
  const uint8_t* Elements(uint32_t count, size_t stride, size_t element_size, const std::string& field) {
    const size_t at = pos_;
    const uint64_t bytes = count == 0 ? 0 : (static_cast<uint64_t>(count) - 1) * stride + element_size;
    if (pos_ > size_ || bytes > size_ - pos_) Fail(field, "(" + std::to_string(count) + " elements)", at);
    pos_ += bytes;
    return data_ + at;
  }
  bool byte_order_big_endian() const { return big_endian_; }

 private:
  void Align(size_t n) {
    const size_t body = pos_ - kEncapsulationSize;
    pos_ += (n - body % n) % n;
  }

  // An unsigned value of `n` bytes in the message's byte order, aligned to `n`.
  uint64_t Primitive(size_t n, const std::string& field) {
    Align(n);
    if (pos_ > size_ || n > size_ - pos_) Fail(field, "(" + std::to_string(n) + " bytes)", pos_);
    uint64_t value = 0;
    for (size_t i = 0; i < n; ++i) value |= uint64_t{data_[pos_ + (big_endian_ ? n - 1 - i : i)]} << (8 * i);
    pos_ += n;
    return value;
  }

  [[noreturn]] void Fail(const std::string& field, const std::string& what, size_t at) const {
    throw std::runtime_error(std::string(type_) + ": field '" + field + "' " + what + " runs past the end of the " +
                             std::to_string(size_) + "-byte message at offset " + std::to_string(at));
  }

  const uint8_t* data_;
  size_t size_;
  const char* type_;
  size_t pos_ = 0;
  bool big_endian_ = false;
};

RosHeader ReadHeader(CdrReader& in) {
  RosHeader header;
  header.stamp.sec = in.I32("header.stamp.sec");
  header.stamp.nsec = in.U32("header.stamp.nanosec");
  header.frame_id = in.String("header.frame_id");
  return header;
}

// At least a string length, offset, datatype and count.
constexpr size_t kMinPointFieldSize = 4 + 4 + 1 + 4;

RosPointField ReadPointField(CdrReader& in, const std::string& prefix) {
  RosPointField field;
  field.name = in.String(prefix + ".name");
  field.offset = in.U32(prefix + ".offset");
  field.datatype = in.U8(prefix + ".datatype");
  field.count = in.U32(prefix + ".count");
  return field;
}

template <size_t N>
void ReadDoubles(CdrReader& in, const std::string& field, std::array<double, N>& values) {
  for (size_t i = 0; i < N; ++i) values[i] = in.F64(field + "[" + std::to_string(i) + "]");
}

// A CustomPoint in CDR: uint32 offset_time, float32 x, y, z, uint8 reflectivity, tag, line (19 bytes),
// padded to 20 before the next one's uint32.
constexpr size_t kLivoxPointSize = 19;
constexpr size_t kLivoxPointStride = 20;

template <typename T>
T LoadScalar(const uint8_t* p, bool big_endian) {
  uint8_t bytes[sizeof(T)];
  for (size_t i = 0; i < sizeof(T); ++i) bytes[i] = big_endian ? p[sizeof(T) - 1 - i] : p[i];
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

RosLivoxPoint LoadLivoxPoint(const uint8_t* p, bool big_endian) {
  RosLivoxPoint point;
  point.offset_time = LoadScalar<uint32_t>(p, big_endian);
  point.x = LoadScalar<float>(p + 4, big_endian);
  point.y = LoadScalar<float>(p + 8, big_endian);
  point.z = LoadScalar<float>(p + 12, big_endian);
  point.reflectivity = p[16];
  point.tag = p[17];
  point.line = p[18];
  return point;
}

}  // namespace

RosLivoxCustomMsg DecodeCdrLivoxCustomMsg(const uint8_t* data, size_t size) {
  CdrReader in(data, size, "livox_ros_driver2/msg/CustomMsg");
  RosLivoxCustomMsg msg;
  msg.header = ReadHeader(in);
  msg.timebase = in.U64("timebase");
  msg.point_num = in.U32("point_num");
  msg.lidar_id = in.U8("lidar_id");
  for (size_t i = 0; i < msg.rsvd.size(); ++i) msg.rsvd[i] = in.U8("rsvd[" + std::to_string(i) + "]");
  const uint32_t count = in.Count("points", kLivoxPointSize, 4);
  const uint8_t* points = in.Elements(count, kLivoxPointStride, kLivoxPointSize, "points");
  msg.points.reserve(count);
  for (uint32_t i = 0; i < count; ++i)
    msg.points.push_back(
        LoadLivoxPoint(points + static_cast<size_t>(i) * kLivoxPointStride, in.byte_order_big_endian()));
  return msg;
}

RosPointCloud2 DecodeCdrPointCloud2(const uint8_t* data, size_t size) {
  CdrReader in(data, size, "sensor_msgs/msg/PointCloud2");
  RosPointCloud2 msg;
  msg.header = ReadHeader(in);
  msg.height = in.U32("height");
  msg.width = in.U32("width");
  const uint32_t fields = in.Count("fields", kMinPointFieldSize);
  for (uint32_t i = 0; i < fields; ++i) msg.fields.push_back(ReadPointField(in, "fields[" + std::to_string(i) + "]"));
  msg.is_bigendian = in.Bool("is_bigendian");
  msg.point_step = in.U32("point_step");
  msg.row_step = in.U32("row_step");
  msg.data = in.Bytes("data");
  msg.is_dense = in.Bool("is_dense");
  return msg;
}

RosImage DecodeCdrImage(const uint8_t* data, size_t size) {
  CdrReader in(data, size, "sensor_msgs/msg/Image");
  RosImage msg;
  msg.header = ReadHeader(in);
  msg.height = in.U32("height");
  msg.width = in.U32("width");
  msg.encoding = in.String("encoding");
  msg.is_bigendian = in.U8("is_bigendian");
  msg.step = in.U32("step");
  msg.data = in.Bytes("data");
  return msg;
}

RosCompressedImage DecodeCdrCompressedImage(const uint8_t* data, size_t size) {
  CdrReader in(data, size, "sensor_msgs/msg/CompressedImage");
  RosCompressedImage msg;
  msg.header = ReadHeader(in);
  msg.format = in.String("format");
  msg.data = in.Bytes("data");
  return msg;
}

RosCameraInfo DecodeCdrCameraInfo(const uint8_t* data, size_t size) {
  CdrReader in(data, size, "sensor_msgs/msg/CameraInfo");
  RosCameraInfo msg;
  msg.header = ReadHeader(in);
  msg.height = in.U32("height");
  msg.width = in.U32("width");
  msg.distortion_model = in.String("distortion_model");
  const uint32_t coefficients = in.Count("d", sizeof(double), sizeof(double));
  for (uint32_t i = 0; i < coefficients; ++i) msg.D.push_back(in.F64("d[" + std::to_string(i) + "]"));
  ReadDoubles(in, "k", msg.K);
  ReadDoubles(in, "r", msg.R);
  ReadDoubles(in, "p", msg.P);
  msg.binning_x = in.U32("binning_x");
  msg.binning_y = in.U32("binning_y");
  msg.roi.x_offset = in.U32("roi.x_offset");
  msg.roi.y_offset = in.U32("roi.y_offset");
  msg.roi.height = in.U32("roi.height");
  msg.roi.width = in.U32("roi.width");
  msg.roi.do_rectify = in.Bool("roi.do_rectify");
  return msg;
}

}  // namespace fusecal
