// fusecal's types as ROS sensor messages (the plain structs of ros_sensor_messages.hpp), the inverse of
// ros_sensor_conversions.hpp: for what fusecal publishes to ROS 2 (the overlay image) and for the peers
// and benchmarks that play a recording as a ROS 2 robot would. Each throws std::runtime_error when the
// input has no ROS form.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "stages/formats/ros_sensor_messages.hpp"
#include "stages/foundation/camera_model.hpp"
#include "stages/foundation/point_cloud.hpp"

namespace fusecal {

// Microseconds since the epoch as a ROS time (seconds and nanoseconds).
RosTime UtimeToRosStamp(int64_t utime);

// CV_8UC1 -> mono8, CV_8UC3 (BGR) -> bgr8, rows packed (step = width x channels).
RosImage ToRosImage(const cv::Mat& image, const RosHeader& header);

// Encoded bytes as they are: `encoding` is "jpeg" or "png".
RosCompressedImage ToRosCompressedImage(const std::vector<uint8_t>& bytes, const std::string& encoding,
                                        const RosHeader& header);

// x, y, z and intensity as float32 (the Velodyne driver's layout), ring as uint16 when the cloud has
// rings; unorganised (height 1), little-endian, dense.
RosPointCloud2 ToRosPointCloud2(const PointCloud& cloud, const RosHeader& header);

// As livox_ros_driver2 publishes a scan: timebase the first point's time (the header stamp plus the
// earliest time offset, the stamp without offsets) and each point's offset_time after it, intensity as
// reflectivity (rounded, clamped to 0..255), ring as line (0 without rings); point_num the point count.
// A ring outside 0..255 or a scan longer than 4.29 s (uint32 nanoseconds) has no CustomMsg form.
RosLivoxCustomMsg ToRosLivoxCustomMsg(const PointCloud& cloud, const RosHeader& header);

// pinhole -> plumb_bob (k1 k2 p1 p2 k3), equidistant -> equidistant (k1..k4); K and P from fx, fy, cx, cy,
// R the identity. An equirectangular panorama has no CameraInfo form.
RosCameraInfo ToRosCameraInfo(const CameraParams& camera, const RosHeader& header);

}  // namespace fusecal
