#include "stages/formats/ros_sensor_conversions.hpp"

#include <climits>
#include <cmath>
#include <cstring>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace fusecal {

namespace {

struct EncodingLayout {
  int cv_type;     // of the message's pixels
  int conversion;  // cv::cvtColor code to BGR / grey, or -1 for none
  bool sixteen_bit;
};

bool LookUpEncoding(const std::string& encoding, EncodingLayout* layout) {
  static const std::vector<std::pair<std::string, EncodingLayout>> kLayouts = {
      {"mono8", {CV_8UC1, -1, false}},
      {"8UC1", {CV_8UC1, -1, false}},
      {"bgr8", {CV_8UC3, -1, false}},
      {"8UC3", {CV_8UC3, -1, false}},
      {"rgb8", {CV_8UC3, cv::COLOR_RGB2BGR, false}},
      {"bgra8", {CV_8UC4, cv::COLOR_BGRA2BGR, false}},
      {"rgba8", {CV_8UC4, cv::COLOR_RGBA2BGR, false}},
      {"mono16", {CV_16UC1, -1, true}},
      {"16UC1", {CV_16UC1, -1, true}},
      {"bgr16", {CV_16UC3, -1, true}},
      {"rgb16", {CV_16UC3, cv::COLOR_RGB2BGR, true}},
      // ROS names a Bayer pattern by its first row, OpenCV by its second: rggb is OpenCV's BG.
      {"bayer_rggb8", {CV_8UC1, cv::COLOR_BayerBG2BGR, false}},
      {"bayer_bggr8", {CV_8UC1, cv::COLOR_BayerRG2BGR, false}},
      {"bayer_gbrg8", {CV_8UC1, cv::COLOR_BayerGR2BGR, false}},
      {"bayer_grbg8", {CV_8UC1, cv::COLOR_BayerGB2BGR, false}},
  };
  for (const auto& [name, entry] : kLayouts)
    if (name == encoding) {
      *layout = entry;
      return true;
    }
  return false;
}

// Bytes of a PointField datatype (1..8: INT8, UINT8, INT16, UINT16, INT32, UINT32, FLOAT32, FLOAT64).
int FieldSize(uint8_t datatype) { return datatype <= 2 ? 1 : datatype <= 4 ? 2 : datatype <= 7 ? 4 : 8; }

// Reads one numeric PointCloud2 field as a double.
double ReadField(const uint8_t* p, uint8_t datatype, bool big_endian) {
  if (datatype == RosPointField::FLOAT32 && !big_endian) {  // the usual layout, a third of an import's time
    float v;
    std::memcpy(&v, p, 4);
    return v;
  }
  uint8_t bytes[8];
  const int size = FieldSize(datatype);
  for (int i = 0; i < size; ++i) bytes[i] = big_endian ? p[size - 1 - i] : p[i];
  switch (datatype) {
    case RosPointField::INT8:
      return static_cast<int8_t>(bytes[0]);
    case RosPointField::UINT8:
      return bytes[0];
    case RosPointField::INT16: {
      int16_t v;
      std::memcpy(&v, bytes, 2);
      return v;
    }
    case RosPointField::UINT16: {
      uint16_t v;
      std::memcpy(&v, bytes, 2);
      return v;
    }
    case RosPointField::INT32: {
      int32_t v;
      std::memcpy(&v, bytes, 4);
      return v;
    }
    case RosPointField::UINT32: {
      uint32_t v;
      std::memcpy(&v, bytes, 4);
      return v;
    }
    case RosPointField::FLOAT32: {
      float v;
      std::memcpy(&v, bytes, 4);
      return v;
    }
    default: {
      double v;
      std::memcpy(&v, bytes, 8);
      return v;
    }
  }
}

const RosPointField* FindField(const RosPointCloud2& msg, std::initializer_list<const char*> names) {
  for (const char* name : names)
    for (const auto& field : msg.fields)
      if (field.name == name) {
        if (field.datatype < 1 || field.datatype > 8)
          throw std::runtime_error("PointCloud2 field '" + field.name + "' has unknown datatype " +
                                   std::to_string(field.datatype));
        // 64-bit: an offset near 2^32 must not wrap round to a small sum.
        if (static_cast<uint64_t>(field.offset) + FieldSize(field.datatype) > msg.point_step)
          throw std::runtime_error("PointCloud2 field '" + field.name + "' lies beyond point_step " +
                                   std::to_string(msg.point_step));
        return &field;
      }
  return nullptr;
}

// A beam index of any field type; one that no int16 holds (or NaN) is corrupt (converting it would be
// undefined behaviour: found by fuzzing, a uint16 ring of 35584).
int16_t RingIndex(double value) {
  if (!(value >= std::numeric_limits<int16_t>::min() && value <= std::numeric_limits<int16_t>::max()))
    throw std::runtime_error("PointCloud2 ring " + std::to_string(value) + " is not a beam index");
  return static_cast<int16_t>(value);
}

// Livox's `timestamp` (float64): each point's absolute time, in nanoseconds (Livox) or seconds (Hesai's
// field of that name). The unit is the one that puts the first point nearer the header stamp: both
// drivers stamp the header with the scan's first point, and an unsynchronised Livox counts nanoseconds
// from power-on, too small for a rule by magnitude. A zero header stamp (the arrival time stands in)
// gives no times: they would be relative to another clock.
class PointTimes {
 public:
  PointTimes(const RosPointCloud2& msg, const RosPointField* field) : msg_(msg), field_(field) {
    if (!field_ || msg.header.stamp.IsZero() || msg.width == 0 || msg.height == 0) {
      field_ = nullptr;
      return;
    }
    stamp_ns_ = static_cast<double>(msg.header.stamp.sec) * 1e9 + msg.header.stamp.nsec;
    const double first = Read(msg.data.data());
    nanoseconds_ = std::abs(first - stamp_ns_) < std::abs(first * 1e9 - stamp_ns_);
  }
  bool present() const { return field_ != nullptr; }
  float OffsetS(const uint8_t* point) const {
    const double t = Read(point);
    return static_cast<float>(nanoseconds_ ? (t - stamp_ns_) * 1e-9 : t - stamp_ns_ * 1e-9);
  }

 private:
  double Read(const uint8_t* point) const {
    const double t = ReadField(point + field_->offset, field_->datatype, msg_.is_bigendian);
    if (!std::isfinite(t)) throw std::runtime_error("PointCloud2 " + field_->name + " is not finite");
    return t;
  }
  const RosPointCloud2& msg_;
  const RosPointField* field_;
  double stamp_ns_ = 0;
  bool nanoseconds_ = true;
};

void CheckCloudSize(const RosPointCloud2& msg) {
  if (msg.point_step == 0 && static_cast<uint64_t>(msg.width) * msg.height > 0)
    throw std::runtime_error("PointCloud2 has point_step 0");
  if (static_cast<uint64_t>(msg.width) * msg.point_step > msg.row_step)
    throw std::runtime_error("PointCloud2 row_step " + std::to_string(msg.row_step) + " is shorter than width " +
                             std::to_string(msg.width) + " x point_step " + std::to_string(msg.point_step));
  if (static_cast<uint64_t>(msg.row_step) * msg.height > msg.data.size())
    throw std::runtime_error("PointCloud2 holds " + std::to_string(msg.data.size()) + " bytes, its header says " +
                             std::to_string(static_cast<uint64_t>(msg.row_step) * msg.height));
}

}  // namespace

int64_t RosStampToUtime(const RosTime& stamp) { return stamp.sec * 1000000 + static_cast<int64_t>(stamp.nsec) / 1000; }

cv::Mat SixteenBitScaler::ToEightBit(const cv::Mat& image16) {
  if (shift_ < 0) {
    double max_value = 0;
    cv::minMaxLoc(image16.reshape(1), nullptr, &max_value);
    int bits = 8;
    while (bits < 16 && max_value >= (1 << bits)) ++bits;
    shift_ = bits - 8;
  }
  cv::Mat image8;
  image16.convertTo(image8, CV_8U, 1.0 / (1 << shift_));
  return image8;
}

cv::Mat RosImageToMat(const RosImage& msg, SixteenBitScaler& scaler) {
  EncodingLayout layout{};
  if (!LookUpEncoding(msg.encoding, &layout))
    throw std::runtime_error("image encoding '" + msg.encoding +
                             "' is not supported (mono8, bgr8, rgb8, bgra8, rgba8, mono16, bgr16, rgb16, "
                             "8UC1, 8UC3, 16UC1, bayer_*8)");
  if (msg.width == 0 || msg.height == 0) throw std::runtime_error("image of size 0");
  // cv::Mat counts rows and columns in int.
  if (msg.width > INT_MAX || msg.height > INT_MAX)
    throw std::runtime_error("image " + std::to_string(msg.width) + "x" + std::to_string(msg.height) + " is too large");
  const size_t row_bytes = static_cast<size_t>(msg.width) * CV_ELEM_SIZE(layout.cv_type);
  if (msg.step < row_bytes || static_cast<size_t>(msg.step) * msg.height > msg.data.size())
    throw std::runtime_error("image " + std::to_string(msg.width) + "x" + std::to_string(msg.height) + " " +
                             msg.encoding + " with step " + std::to_string(msg.step) + " does not fit its " +
                             std::to_string(msg.data.size()) + " bytes");
  cv::Mat pixels(static_cast<int>(msg.height), static_cast<int>(msg.width), layout.cv_type,
                 const_cast<uint8_t*>(msg.data.data()), msg.step);
  cv::Mat image = pixels.clone();  // own the bytes: the message goes away
  if (layout.sixteen_bit) {
    if (msg.is_bigendian) {
      uint16_t* p = image.ptr<uint16_t>();
      for (size_t i = 0; i < image.total() * image.channels(); ++i)
        p[i] = static_cast<uint16_t>((p[i] >> 8) | (p[i] << 8));
    }
    image = scaler.ToEightBit(image);
  }
  if (layout.conversion >= 0) cv::cvtColor(image, image, layout.conversion);
  return image;
}

std::string RosCompressedFormat(const RosCompressedImage& msg, cv::Mat* decoded) {
  const std::string& format = msg.format;
  std::string encoding;
  if (format.find("compressedDepth") != std::string::npos)
    throw std::runtime_error("CompressedImage format '" + format + "' is a depth image, not a camera image");
  if (format.find("jpeg") != std::string::npos || format.find("jpg") != std::string::npos) encoding = "jpeg";
  if (format.find("png") != std::string::npos) encoding = "png";
  if (encoding.empty())
    throw std::runtime_error("CompressedImage format '" + format + "' is not supported (jpeg or png)");
  *decoded = cv::imdecode(msg.data, cv::IMREAD_COLOR);
  if (decoded->empty())
    throw std::runtime_error("CompressedImage (" + format + ", " + std::to_string(msg.data.size()) +
                             " bytes) does not decode");
  return encoding;
}

PointCloud RosCloudToPointCloud(const RosPointCloud2& msg, int* dropped) {
  const auto* x = FindField(msg, {"x"});
  const auto* y = FindField(msg, {"y"});
  const auto* z = FindField(msg, {"z"});
  if (!x || !y || !z) {
    std::string names;
    for (const auto& field : msg.fields) names += (names.empty() ? "" : ", ") + field.name;
    throw std::runtime_error("PointCloud2 needs fields x, y, z; it has: " + (names.empty() ? "none" : names));
  }
  const auto* intensity = FindField(msg, {"intensity", "i"});
  const auto* ring = FindField(msg, {"ring", "line"});
  CheckCloudSize(msg);
  const PointTimes times(msg, FindField(msg, {"timestamp"}));
  PointCloud cloud;
  // No points: do not walk 2^32 empty rows (row_step 0 lets any height pass the size check).
  if (msg.width == 0 || msg.height == 0) {
    if (dropped) *dropped = 0;
    return cloud;
  }
  int skipped = 0;
  const size_t points = static_cast<size_t>(msg.width) * msg.height;  // CheckCloudSize: the data holds them
  cloud.points.reserve(points);
  if (intensity) cloud.intensity.reserve(points);
  for (uint32_t row = 0; row < msg.height; ++row)
    for (uint32_t col = 0; col < msg.width; ++col) {
      const uint8_t* point =
          msg.data.data() + static_cast<size_t>(row) * msg.row_step + static_cast<size_t>(col) * msg.point_step;
      const Eigen::Vector3f p(static_cast<float>(ReadField(point + x->offset, x->datatype, msg.is_bigendian)),
                              static_cast<float>(ReadField(point + y->offset, y->datatype, msg.is_bigendian)),
                              static_cast<float>(ReadField(point + z->offset, z->datatype, msg.is_bigendian)));
      if (!p.allFinite() || p.squaredNorm() == 0.0f) {
        ++skipped;
        continue;
      }
      cloud.points.push_back(p);
      if (intensity)
        cloud.intensity.push_back(
            static_cast<float>(ReadField(point + intensity->offset, intensity->datatype, msg.is_bigendian)));
      if (ring) cloud.ring.push_back(RingIndex(ReadField(point + ring->offset, ring->datatype, msg.is_bigendian)));
      if (times.present()) cloud.time_offset_s.push_back(times.OffsetS(point));
    }
  if (dropped) *dropped = skipped;
  return cloud;
}

CameraParams RosCameraInfoToParams(const RosCameraInfo& msg) {
  CameraParams p;
  const std::string& model = msg.distortion_model;
  const auto& D = msg.D;
  if (model == "equidistant") {
    if (D.size() != 4)
      throw std::runtime_error("CameraInfo equidistant needs 4 coefficients, has " + std::to_string(D.size()));
    p.model = "equidistant";
  } else if (model == "plumb_bob" || model == "rational_polynomial" || (model.empty() && D.empty())) {
    if (D.size() > 5 && (D.size() != 8 || D[5] != 0 || D[6] != 0 || D[7] != 0))
      throw std::runtime_error("CameraInfo " + model + " with nonzero k4..k6 is not supported (plumb_bob's 5 only)");
    p.model = "pinhole";
  } else {
    throw std::runtime_error("CameraInfo distortion model '" + model +
                             "' is not supported (plumb_bob, rational_polynomial with k4..k6 = 0, equidistant)");
  }
  for (size_t i = 0; i < std::min<size_t>(D.size(), p.model == "equidistant" ? 4 : 5); ++i) p.dist[i] = D[i];
  p.width = static_cast<int>(msg.width);
  p.height = static_cast<int>(msg.height);
  p.fx = msg.K[0];
  p.fy = msg.K[4];
  p.cx = msg.K[2];
  p.cy = msg.K[5];
  if (p.fx == 0 && p.fy == 0) throw std::runtime_error("CameraInfo has K = 0: the camera is not calibrated");
  if (msg.binning_x > 1 || msg.binning_y > 1 || msg.roi.width > 0)
    throw std::runtime_error("CameraInfo with binning or a region of interest is not supported");
  const std::string error = p.Validate();
  if (!error.empty()) throw std::runtime_error("CameraInfo: " + error);
  return p;
}

}  // namespace fusecal
