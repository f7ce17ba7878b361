#include "stages/formats/conversions.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "stages/formats/image_header.hpp"

namespace fusecal {

bool IsKnownImageEncoding(const std::string& e) {
  return e == "mono8" || e == "rgb8" || e == "bgr8" || e == "jpeg" || e == "png";
}

namespace {

cv::Mat DecodeRaw(const image_t& msg, int channels) {
  if (msg.width <= 0 || msg.height <= 0)
    throw ConversionError("image of " + msg.encoding + " has no size (" + std::to_string(msg.width) + "x" +
                          std::to_string(msg.height) + ")");
  const int64_t row_bytes = int64_t(msg.width) * channels;
  const int64_t step = msg.step > 0 ? msg.step : row_bytes;
  // Divided, not multiplied: step x height can exceed 64 bits (found by fuzzing: 5105605947 x 1869479942).
  if (step < row_bytes || int64_t(msg.data.size()) / step < msg.height)
    throw ConversionError("image " + std::to_string(msg.width) + "x" + std::to_string(msg.height) + " " + msg.encoding +
                          " needs " + std::to_string(msg.height) + " rows of " + std::to_string(step) + " bytes, has " +
                          std::to_string(msg.data.size()) + " bytes");
  const cv::Mat view(msg.height, msg.width, CV_8UC(channels), const_cast<uint8_t*>(msg.data.data()),
                     static_cast<size_t>(step));
  return view.clone();
}

// The largest compressed image decoded: 8192 x 8192 (192 MB as BGR); the cameras here give 2-33 Mpixel.
constexpr int64_t kMaxCompressedImagePixels = int64_t(8192) * 8192;

// cv::imdecode decodes whatever format it recognises in the bytes and allocates the size their header
// declares (found by fuzzing: a 1 KB JPEG in a STATION made it allocate 2.3 GB). So the bytes must be
// of the format `encoding` names, with a size in bounds, before they reach it.
void CheckCompressedImage(const image_t& msg) {
  if (msg.data.empty()) throw ConversionError(msg.encoding + " image has no data");
  const auto size = CompressedImageSize(msg.data, msg.encoding);
  if (!size) throw ConversionError("corrupt " + msg.encoding + " image data (no valid " + msg.encoding + " header)");
  if (int64_t(size->width) * size->height > kMaxCompressedImagePixels)
    throw ConversionError(msg.encoding + " image of " + std::to_string(size->width) + "x" +
                          std::to_string(size->height) + " pixels is larger than 8192x8192");
}

}  // namespace

cv::Mat ImageToMat(const image_t& msg) {
  if (msg.encoding == "mono8") return DecodeRaw(msg, 1);
  if (msg.encoding == "bgr8") return DecodeRaw(msg, 3);
  if (msg.encoding == "rgb8") {
    cv::Mat bgr;
    cv::cvtColor(DecodeRaw(msg, 3), bgr, cv::COLOR_RGB2BGR);
    return bgr;
  }
  if (msg.encoding == "jpeg" || msg.encoding == "png") {
    CheckCompressedImage(msg);
    cv::Mat decoded = cv::imdecode(msg.data, cv::IMREAD_UNCHANGED);
    if (decoded.empty()) throw ConversionError("corrupt " + msg.encoding + " image data");
    if (decoded.depth() != CV_8U) decoded.convertTo(decoded, CV_8U, 1.0 / 256.0);
    if (decoded.channels() == 4) cv::cvtColor(decoded, decoded, cv::COLOR_BGRA2BGR);
    return decoded;
  }
  throw ConversionError("unknown image encoding '" + msg.encoding + "' (expected mono8, rgb8, bgr8, jpeg or png)");
}

int64_t PeekUtime(const uint8_t* data, size_t size) {
  if (size < 16) return -1;
  uint64_t v = 0;
  for (int k = 8; k < 16; ++k) v = (v << 8) | data[k];
  return static_cast<int64_t>(v);
}

cv::Mat ImageToMatReduced(const image_t& msg, int min_width) {
  if (msg.encoding != "jpeg") return ImageToMat(msg);
  CheckCompressedImage(msg);
  int flag = cv::IMREAD_GRAYSCALE;
  if (msg.width >= 8 * min_width)
    flag = cv::IMREAD_REDUCED_GRAYSCALE_8;
  else if (msg.width >= 4 * min_width)
    flag = cv::IMREAD_REDUCED_GRAYSCALE_4;
  else if (msg.width >= 2 * min_width)
    flag = cv::IMREAD_REDUCED_GRAYSCALE_2;
  cv::Mat decoded = cv::imdecode(msg.data, flag);
  if (decoded.empty()) throw ConversionError("corrupt jpeg image data");
  return decoded;
}

image_t MatToImage(const cv::Mat& image, const std::string& encoding, int64_t utime, const std::string& frame_id) {
  if (image.empty()) throw ConversionError("cannot encode an empty image");
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    throw ConversionError("only 8-bit grey or BGR images can be encoded");
  if (!IsKnownImageEncoding(encoding)) throw ConversionError("unknown image encoding '" + encoding + "'");
  image_t msg{};
  msg.utime = utime;
  msg.frame_id = frame_id;
  msg.width = image.cols;
  msg.height = image.rows;
  msg.encoding = encoding;
  cv::Mat pixels = image;
  if (encoding == "jpeg" || encoding == "png") {
    if (!cv::imencode(encoding == "jpeg" ? ".jpg" : ".png", image, msg.data))
      throw ConversionError("OpenCV could not encode " + encoding);
    msg.step = 0;
  } else {
    if (encoding == "mono8" && image.channels() == 3) cv::cvtColor(image, pixels, cv::COLOR_BGR2GRAY);
    if (encoding != "mono8" && image.channels() == 1) cv::cvtColor(image, pixels, cv::COLOR_GRAY2BGR);
    if (encoding == "rgb8") {
      cv::Mat rgb;  // never convert in place: `pixels` may share the caller's buffer
      cv::cvtColor(pixels, rgb, cv::COLOR_BGR2RGB);
      pixels = rgb;
    }
    if (!pixels.isContinuous()) pixels = pixels.clone();
    msg.step = static_cast<int32_t>(pixels.cols * pixels.elemSize());
    msg.data.assign(pixels.datastart, pixels.dataend);
  }
  msg.size = static_cast<int32_t>(msg.data.size());
  return msg;
}

PointCloud CloudFromMsg(const point_cloud_t& msg) {
  const size_t n = static_cast<size_t>(msg.num_points);
  if (msg.num_points < 0 || msg.x.size() != n || msg.y.size() != n || msg.z.size() != n)
    throw ConversionError("point cloud arrays do not match num_points=" + std::to_string(msg.num_points));
  auto check_optional = [n](size_t count, const char* name) {
    if (count != 0 && count != n)
      throw ConversionError(std::string("point cloud field '") + name + "' has " + std::to_string(count) +
                            " entries for " + std::to_string(n) + " points");
  };
  check_optional(msg.intensity.size(), "intensity");
  check_optional(msg.ring.size(), "ring");
  check_optional(msg.time_offset_s.size(), "time_offset_s");
  PointCloud cloud;
  cloud.points.resize(n);
  for (size_t i = 0; i < n; ++i) cloud.points[i] = Eigen::Vector3f(msg.x[i], msg.y[i], msg.z[i]);
  cloud.intensity = msg.intensity;
  cloud.ring = msg.ring;
  cloud.time_offset_s = msg.time_offset_s;
  return cloud;
}

point_cloud_t CloudToMsg(const PointCloud& cloud, int64_t utime, const std::string& frame_id) {
  const size_t n = cloud.size();
  for (size_t count : {cloud.intensity.size(), cloud.ring.size(), cloud.time_offset_s.size()})
    if (count != 0 && count != n)
      throw ConversionError("point cloud optional field length " + std::to_string(count) + " does not match " +
                            std::to_string(n) + " points");
  point_cloud_t msg{};
  msg.utime = utime;
  msg.frame_id = frame_id;
  msg.num_points = static_cast<int32_t>(n);
  msg.x.resize(n);
  msg.y.resize(n);
  msg.z.resize(n);
  for (size_t i = 0; i < n; ++i) {
    msg.x[i] = cloud.points[i].x();
    msg.y[i] = cloud.points[i].y();
    msg.z[i] = cloud.points[i].z();
  }
  msg.intensity = cloud.intensity;
  msg.num_intensity = static_cast<int32_t>(cloud.intensity.size());
  msg.ring = cloud.ring;
  msg.num_ring = static_cast<int32_t>(cloud.ring.size());
  msg.time_offset_s = cloud.time_offset_s;
  msg.num_time_offset = static_cast<int32_t>(cloud.time_offset_s.size());
  return msg;
}

CameraParams CameraFromMsg(const camera_info_t& msg) {
  CameraParams p;
  p.model = msg.model;
  p.width = msg.width;
  p.height = msg.height;
  p.fx = msg.fx;
  p.fy = msg.fy;
  p.cx = msg.cx;
  p.cy = msg.cy;
  for (int i = 0; i < 5; ++i) p.dist[i] = msg.dist[i];
  const std::string error = p.Validate();
  if (!error.empty()) throw ConversionError("camera_info: " + error);
  return p;
}

camera_info_t CameraToMsg(const CameraParams& p, int64_t utime) {
  camera_info_t msg{};
  msg.utime = utime;
  msg.model = p.model;
  msg.width = p.width;
  msg.height = p.height;
  msg.fx = p.fx;
  msg.fy = p.fy;
  msg.cx = p.cx;
  msg.cy = p.cy;
  for (int i = 0; i < 5; ++i) msg.dist[i] = p.dist[i];
  return msg;
}

void Matrix6ToArray(const Matrix6& m, double out[36]) {
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) out[r * 6 + c] = m(r, c);
}

Matrix6 Matrix6FromArray(const double in[36]) {
  Matrix6 m;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) m(r, c) = in[r * 6 + c];
  return m;
}

}  // namespace fusecal
