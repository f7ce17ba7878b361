#include "tests/support/cdr_writer.hpp"

#include <cstring>

namespace fusecal::testing {

namespace {
constexpr size_t kEncapsulationSize = 4;
}  // namespace

CdrWriter::CdrWriter(CdrByteOrder order) : big_endian_(order == CdrByteOrder::kBig) {
  bytes_ = {0x00, static_cast<uint8_t>(big_endian_ ? 0x00 : 0x01), 0x00, 0x00};
}

void CdrWriter::Align(size_t n) {
  while ((bytes_.size() - kEncapsulationSize) % n != 0) bytes_.push_back(0);
}

void CdrWriter::Put(uint64_t value, size_t n) {
  Align(n);
  for (size_t i = 0; i < n; ++i) {
    const size_t shift = 8 * (big_endian_ ? n - 1 - i : i);
    bytes_.push_back(static_cast<uint8_t>(value >> shift));
  }
}

void CdrWriter::U8(uint8_t value) { Put(value, 1); }
void CdrWriter::U32(uint32_t value) { Put(value, 4); }
void CdrWriter::U64(uint64_t value) { Put(value, 8); }

void CdrWriter::F32(float value) {
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  Put(bits, 4);
}

void CdrWriter::F64(double value) {
  uint64_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  Put(bits, 8);
}

void CdrWriter::String(const std::string& value) {
  U32(static_cast<uint32_t>(value.size() + 1));
  bytes_.insert(bytes_.end(), value.begin(), value.end());
  bytes_.push_back(0);
}

void CdrWriter::Bytes(const std::vector<uint8_t>& values) {
  U32(static_cast<uint32_t>(values.size()));
  bytes_.insert(bytes_.end(), values.begin(), values.end());
}

void CdrWriter::Header(const RosHeader& header) {
  I32(static_cast<int32_t>(header.stamp.sec));
  U32(header.stamp.nsec);
  String(header.frame_id);
}

std::vector<uint8_t> EncodeCdr(const RosPointCloud2& msg, CdrByteOrder order) {
  CdrWriter out(order);
  out.Header(msg.header);
  out.U32(msg.height);
  out.U32(msg.width);
  out.U32(static_cast<uint32_t>(msg.fields.size()));
  for (const RosPointField& field : msg.fields) {
    out.String(field.name);
    out.U32(field.offset);
    out.U8(field.datatype);
    out.U32(field.count);
  }
  out.U8(msg.is_bigendian);
  out.U32(msg.point_step);
  out.U32(msg.row_step);
  out.Bytes(msg.data);
  out.U8(msg.is_dense);
  return out.bytes();
}

std::vector<uint8_t> EncodeCdr(const RosImage& msg, CdrByteOrder order) {
  CdrWriter out(order);
  out.Header(msg.header);
  out.U32(msg.height);
  out.U32(msg.width);
  out.String(msg.encoding);
  out.U8(msg.is_bigendian);
  out.U32(msg.step);
  out.Bytes(msg.data);
  return out.bytes();
}

std::vector<uint8_t> EncodeCdr(const RosCompressedImage& msg, CdrByteOrder order) {
  CdrWriter out(order);
  out.Header(msg.header);
  out.String(msg.format);
  out.Bytes(msg.data);
  return out.bytes();
}

std::vector<uint8_t> EncodeCdr(const RosCameraInfo& msg, CdrByteOrder order) {
  CdrWriter out(order);
  out.Header(msg.header);
  out.U32(msg.height);
  out.U32(msg.width);
  out.String(msg.distortion_model);
  out.U32(static_cast<uint32_t>(msg.D.size()));
  for (double d : msg.D) out.F64(d);
  for (double k : msg.K) out.F64(k);
  for (double r : msg.R) out.F64(r);
  for (double p : msg.P) out.F64(p);
  out.U32(msg.binning_x);
  out.U32(msg.binning_y);
  out.U32(msg.roi.x_offset);
  out.U32(msg.roi.y_offset);
  out.U32(msg.roi.height);
  out.U32(msg.roi.width);
  out.U8(msg.roi.do_rectify);
  return out.bytes();
}

std::vector<uint8_t> EncodeCdr(const RosLivoxCustomMsg& msg, CdrByteOrder order) {
  CdrWriter out(order);
  out.Header(msg.header);
  out.U64(msg.timebase);
  out.U32(msg.point_num);
  out.U8(msg.lidar_id);
  for (const uint8_t reserved : msg.rsvd) out.U8(reserved);
  out.U32(static_cast<uint32_t>(msg.points.size()));
  for (const RosLivoxPoint& point : msg.points) {
    out.U32(point.offset_time);
    out.F32(point.x);
    out.F32(point.y);
    out.F32(point.z);
    out.U8(point.reflectivity);
    out.U8(point.tag);
    out.U8(point.line);
  }
  return out.bytes();
}

}  // namespace fusecal::testing
