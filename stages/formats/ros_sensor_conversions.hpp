// ROS sensor messages (ros_sensor_messages.hpp, from ROS 1 or ROS 2) into fusecal's types.
// Every function throws std::runtime_error with a message saying what is wrong with the message; sizes
// and offsets from the message are checked in 64 bits, so that none wraps round to a small sum.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "stages/formats/ros_sensor_messages.hpp"
#include "stages/foundation/camera_model.hpp"
#include "stages/foundation/point_cloud.hpp"

namespace fusecal {

// Header stamp in microseconds since the epoch (0 when the stamp is zero: the caller falls back).
int64_t RosStampToUtime(const RosTime& stamp);

// 16-bit images become 8-bit by one shift for the whole recording, chosen from the first 16-bit image
// (its brightest pixel's bit count minus 8), so that brightness does not jump between frames.
class SixteenBitScaler {
 public:
  cv::Mat ToEightBit(const cv::Mat& image16);
  int shift() const { return shift_; }

 private:
  int shift_ = -1;  // not chosen yet
};

// sensor_msgs/Image -> CV_8UC1 or CV_8UC3 (BGR). Encodings: mono8, 8UC1, bgr8, rgb8, 8UC3, bgra8, rgba8,
// mono16, 16UC1, bgr16, rgb16 (through `scaler`), bayer_rggb8/bggr8/gbrg8/grbg8. Honours step and
// is_bigendian.
cv::Mat RosImageToMat(const RosImage& msg, SixteenBitScaler& scaler);

// sensor_msgs/CompressedImage: "jpeg" or "png" (also "bgr8; jpeg compressed bgr8" as image_transport
// writes it). Returns the encoding for image_t and decodes the image into *decoded (to check it).
std::string RosCompressedFormat(const RosCompressedImage& msg, cv::Mat* decoded);

// sensor_msgs/PointCloud2 with fields x, y, z (any numeric type, any offsets, organised or not),
// optionally intensity (or i), ring (or Livox's line) and Livox's timestamp (absolute: in nanoseconds or
// seconds, whichever puts the first point nearer the header stamp; time_offset_s is the point's time
// minus the header stamp, none when the stamp is zero). Other fields (Livox's tag) are ignored. Points
// with a non-finite or all-zero position (no return) are left out and counted in *dropped.
PointCloud RosCloudToPointCloud(const RosPointCloud2& msg, int* dropped = nullptr);

// sensor_msgs/CameraInfo: plumb_bob (or rational_polynomial with k4..k6 = 0) -> pinhole; equidistant ->
// equidistant; K for the intrinsics (the image is assumed unrectified, as image_raw is).
CameraParams RosCameraInfoToParams(const RosCameraInfo& msg);

}  // namespace fusecal
