#include "stages/formats/ros_sensor_frames.hpp"

#include <stdexcept>
#include <utility>

#include "stages/formats/livox_conversions.hpp"

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
  int dropped = 0;
  PointCloud cloud = RosCloudToPointCloud(msg, &dropped);
  return Scan(std::move(cloud), dropped, msg.header, arrival_utime);
}

SensorScan RosSensorFrames::Cloud(const RosLivoxCustomMsg& msg, int64_t arrival_utime) {
  int dropped = 0;
  PointCloud cloud = LivoxCustomMsgToPointCloud(msg, &dropped);
  return Scan(std::move(cloud), dropped, msg.header, arrival_utime);
}

SensorScan RosSensorFrames::Scan(PointCloud cloud, int dropped, const RosHeader& header, int64_t arrival_utime) {
  if (cloud.empty()) throw std::runtime_error("no finite point in " + std::to_string(dropped));
  SensorScan scan;
  scan.cloud = std::move(cloud);
  scan.dropped = dropped;
  scan.utime = Stamp(header.stamp, arrival_utime);
  scan.frame_id = header.frame_id;
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
