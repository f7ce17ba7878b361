#include "formats/ros_sensor_frames.hpp"

#include <stdexcept>

namespace fusecal {

SensorImage RosSensorFrames::Image(const RosImage& msg, int64_t arrival_utime) {
  SensorImage image;
  image.pixels = RosImageToMat(msg, scaler_);
  image.width = image.pixels.cols;
  image.height = image.pixels.rows;
  CheckSize(image.width, image.height);
  image.utime = Stamp(msg.header.stamp, arrival_utime);
  image.frame_id = msg.header.frame_id;
  return image;
}

SensorImage RosSensorFrames::Image(RosCompressedImage msg, int64_t arrival_utime) {
  SensorImage image;
  cv::Mat decoded;
  image.encoding = RosCompressedFormat(msg, &decoded);
  image.width = decoded.cols;
  image.height = decoded.rows;
  CheckSize(image.width, image.height);
  image.utime = Stamp(msg.header.stamp, arrival_utime);
  image.frame_id = msg.header.frame_id;
  image.encoded = std::move(msg.data);
  return image;
}

SensorScan RosSensorFrames::Cloud(const RosPointCloud2& msg, int64_t arrival_utime) {
  SensorScan scan;
  scan.cloud = RosCloudToPointCloud(msg, &scan.dropped);
  if (scan.cloud.empty()) throw std::runtime_error("no finite point in " + std::to_string(scan.dropped));
  scan.utime = Stamp(msg.header.stamp, arrival_utime);
  scan.frame_id = msg.header.frame_id;
  return scan;
}

void RosSensorFrames::CheckSize(int width, int height) const {
  if (camera_ && (width != camera_->width || height != camera_->height))
    throw std::runtime_error("image is " + std::to_string(width) + "x" + std::to_string(height) +
                             ", the camera model is " + std::to_string(camera_->width) + "x" +
                             std::to_string(camera_->height));
}

// The header stamp (when the sensor measured), else the arrival time.
int64_t RosSensorFrames::Stamp(const RosTime& stamp, int64_t arrival_utime) {
  if (!stamp.IsZero()) return RosStampToUtime(stamp);
  ++unstamped_;
  return arrival_utime;
}

}  // namespace fusecal
