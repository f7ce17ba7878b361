#include "stages/formats/ros_sensor_encode.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace fusecal {

RosTime UtimeToRosStamp(int64_t utime) {
  int64_t sec = utime / 1000000, usec = utime % 1000000;
  if (usec < 0) {
    usec += 1000000;
    --sec;
  }
  return RosTime{sec, static_cast<uint32_t>(usec * 1000)};
}

RosImage ToRosImage(const cv::Mat& image, const RosHeader& header) {
  if (image.empty()) throw std::runtime_error("an empty image has no sensor_msgs/Image form");
  if (image.type() != CV_8UC1 && image.type() != CV_8UC3)
    throw std::runtime_error("only 8-bit mono and BGR images become sensor_msgs/Image (OpenCV type " +
                             std::to_string(image.type()) + ")");
  RosImage msg;
  msg.header = header;
  msg.height = static_cast<uint32_t>(image.rows);
  msg.width = static_cast<uint32_t>(image.cols);
  msg.encoding = image.channels() == 1 ? "mono8" : "bgr8";
  msg.step = static_cast<uint32_t>(image.cols * image.elemSize());
  msg.data.resize(static_cast<size_t>(msg.step) * image.rows);
  for (int r = 0; r < image.rows; ++r) std::memcpy(&msg.data[r * msg.step], image.ptr(r), msg.step);
  return msg;
}

RosCompressedImage ToRosCompressedImage(const std::vector<uint8_t>& bytes, const std::string& encoding,
                                        const RosHeader& header) {
  if (encoding != "jpeg" && encoding != "png")
    throw std::runtime_error("a '" + encoding + "' image has no sensor_msgs/CompressedImage form (jpeg or png)");
  RosCompressedImage msg;
  msg.header = header;
  msg.format = encoding;
  msg.data = bytes;
  return msg;
}

RosPointCloud2 ToRosPointCloud2(const PointCloud& cloud, const RosHeader& header) {
  const bool rings = !cloud.ring.empty();
  if ((cloud.HasIntensity() && cloud.intensity.size() != cloud.size()) || (rings && cloud.ring.size() != cloud.size()))
    throw std::runtime_error("cloud of " + std::to_string(cloud.size()) + " points has " +
                             std::to_string(cloud.intensity.size()) + " intensities and " +
                             std::to_string(cloud.ring.size()) + " rings");
  RosPointCloud2 msg;
  msg.header = header;
  msg.height = 1;
  msg.width = static_cast<uint32_t>(cloud.size());
  msg.fields = {{"x", 0, RosPointField::FLOAT32, 1},
                {"y", 4, RosPointField::FLOAT32, 1},
                {"z", 8, RosPointField::FLOAT32, 1},
                {"intensity", 12, RosPointField::FLOAT32, 1}};
  msg.point_step = 16;
  if (rings) {
    msg.fields.push_back({"ring", 16, RosPointField::UINT16, 1});
    msg.point_step = 18;
  }
  msg.row_step = msg.point_step * msg.width;
  msg.is_dense = true;
  msg.data.assign(static_cast<size_t>(msg.row_step), 0);
  for (size_t i = 0; i < cloud.size(); ++i) {
    uint8_t* point = &msg.data[i * msg.point_step];
    const float values[4] = {cloud.points[i].x(), cloud.points[i].y(), cloud.points[i].z(),
                             cloud.HasIntensity() ? cloud.intensity[i] : 0.0f};
    std::memcpy(point, values, sizeof(values));
    if (rings) {
      const uint16_t ring = static_cast<uint16_t>(cloud.ring[i]);
      std::memcpy(point + 16, &ring, 2);
    }
  }
  return msg;
}

RosLivoxCustomMsg ToRosLivoxCustomMsg(const PointCloud& cloud, const RosHeader& header) {
  const bool timed = cloud.time_offset_s.size() == cloud.size() && !cloud.empty();
  const double first_s = timed ? *std::min_element(cloud.time_offset_s.begin(), cloud.time_offset_s.end()) : 0.0;
  RosLivoxCustomMsg msg;
  msg.header = header;
  const int64_t stamp_ns = header.stamp.sec * 1000000000 + header.stamp.nsec;
  msg.timebase = static_cast<uint64_t>(stamp_ns + std::llround(first_s * 1e9));
  msg.point_num = static_cast<uint32_t>(cloud.size());
  msg.points.resize(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) {
    RosLivoxPoint& point = msg.points[i];
    point.x = cloud.points[i].x();
    point.y = cloud.points[i].y();
    point.z = cloud.points[i].z();
    if (i < cloud.intensity.size())
      point.reflectivity = static_cast<uint8_t>(std::clamp(std::lround(cloud.intensity[i]), 0L, 255L));
    if (i < cloud.ring.size()) {
      if (cloud.ring[i] < 0 || cloud.ring[i] > 255)
        throw std::runtime_error("ring " + std::to_string(cloud.ring[i]) + " has no Livox line form (0..255)");
      point.line = static_cast<uint8_t>(cloud.ring[i]);
    }
    const long long offset_ns = timed ? std::llround((cloud.time_offset_s[i] - first_s) * 1e9) : 0;
    if (offset_ns > 0xFFFFFFFFLL) throw std::runtime_error("a scan longer than 4.29 s has no CustomMsg form");
    point.offset_time = static_cast<uint32_t>(offset_ns);
  }
  return msg;
}

RosCameraInfo ToRosCameraInfo(const CameraParams& camera, const RosHeader& header) {
  if (!camera.HasIntrinsics())
    throw std::runtime_error("a '" + camera.model + "' camera has no sensor_msgs/CameraInfo form");
  RosCameraInfo msg;
  msg.header = header;
  msg.width = static_cast<uint32_t>(camera.width);
  msg.height = static_cast<uint32_t>(camera.height);
  if (camera.model == "equidistant") {
    msg.distortion_model = "equidistant";
    msg.D.assign(camera.dist.begin(), camera.dist.begin() + 4);
  } else {
    msg.distortion_model = "plumb_bob";
    msg.D.assign(camera.dist.begin(), camera.dist.end());
  }
  msg.K = {camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1};
  msg.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  msg.P = {camera.fx, 0, camera.cx, 0, 0, camera.fy, camera.cy, 0, 0, 0, 1, 0};
  return msg;
}

}  // namespace fusecal
