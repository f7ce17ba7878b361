// ROS sensor messages (ros_sensor_messages.hpp) into the frames fusecal's streams carry, one code path
// for `fusecal import rosbag` (ROS 1 and ROS 2 bags) and the live ROS 2 input: the stamp rule, the image
// decoding, the check against the camera model, the cloud conversion (PointCloud2 or Livox's CustomMsg).
// Each call throws std::runtime_error saying what is wrong with the message; the caller skips it and
// counts.
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "stages/formats/ros_sensor_conversions.hpp"

namespace fusecal {

// A camera frame: raw pixels (encoded empty), or compressed bytes kept as they are (encoding "jpeg" or
// "png", pixels left empty once checked).
struct SensorImage {
  int64_t utime = 0;
  cv::Mat pixels;
  std::vector<uint8_t> encoded;
  std::string encoding;
  int width = 0, height = 0;
  std::string frame_id;  // the header's: the camera's optical frame
};

struct SensorScan {
  int64_t utime = 0;
  PointCloud cloud;
  int dropped = 0;       // points without a return (non-finite or at the origin)
  std::string frame_id;  // the header's: the LiDAR's frame
};

class RosSensorFrames {
 public:
  // Images are checked against `camera` once it is known (SetCamera); before that, any size passes.
  explicit RosSensorFrames(std::optional<CameraParams> camera = std::nullopt) : camera_(std::move(camera)) {}
  void SetCamera(const CameraParams& camera) { camera_ = camera; }
  const std::optional<CameraParams>& camera() const { return camera_; }

  // `arrival_utime` stands in for a zero header stamp (counted in unstamped()).
  SensorImage Image(const RosImage& msg, int64_t arrival_utime);
  SensorImage Image(RosCompressedImage msg, int64_t arrival_utime);
  SensorScan Cloud(const RosPointCloud2& msg, int64_t arrival_utime);
  SensorScan Cloud(const RosLivoxCustomMsg& msg, int64_t arrival_utime);

  int unstamped() const { return unstamped_; }
  int sixteen_bit_shift() const { return scaler_.shift(); }

 private:
  void CheckSize(int width, int height) const;
  SensorScan Scan(PointCloud cloud, int dropped, const RosHeader& header, int64_t arrival_utime);
  int64_t Stamp(const RosTime& stamp, int64_t arrival_utime);

  std::optional<CameraParams> camera_;
  SixteenBitScaler scaler_;
  int unstamped_ = 0;
};

}  // namespace fusecal
