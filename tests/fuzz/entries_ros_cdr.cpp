// Fuzz entries of ROS sensor messages (fuzz_entries.hpp), as a ROS 2 bag or DDS hands them over (CDR)
// and, for Livox's CustomMsg, as a ROS 1 bag does: decoded (formats/ros_cdr.hpp,
// formats/ros1_serialized.hpp), then converted as `fusecal import rosbag` converts them.
#include "fuzz_entries.hpp"
#include "fuzz_support.hpp"
#include "stages/formats/livox_conversions.hpp"
#include "stages/formats/ros1_serialized.hpp"
#include "stages/formats/ros_cdr.hpp"
#include "stages/formats/ros_sensor_conversions.hpp"

namespace fusecal::fuzz {

// The first byte chooses the message type (its value modulo 4: PointCloud2, Image, CompressedImage,
// CameraInfo); the rest is the serialized message with its encapsulation header.
int FuzzOneRosCdr(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const uint8_t* message = data + 1;
  const size_t length = size - 1;
  switch (data[0] % 4) {
    case 0:
      IgnoringRejection([&] { RosCloudToPointCloud(DecodeCdrPointCloud2(message, length)); });
      break;
    case 1:
      IgnoringRejection([&] {
        SixteenBitScaler scaler;
        RosImageToMat(DecodeCdrImage(message, length), scaler);
      });
      break;
    case 2:
      IgnoringRejection([&] {
        cv::Mat decoded;
        RosCompressedFormat(DecodeCdrCompressedImage(message, length), &decoded);
      });
      break;
    default:
      IgnoringRejection([&] { RosCameraInfoToParams(DecodeCdrCameraInfo(message, length)); });
  }
  return 0;
}

// The first byte chooses the form (even: CDR, odd: ROS 1); the rest is the serialized CustomMsg.
int FuzzOneRosLivox(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const uint8_t* message = data + 1;
  const size_t length = size - 1;
  IgnoringRejection([&] {
    LivoxCustomMsgToPointCloud(data[0] % 2 == 0 ? DecodeCdrLivoxCustomMsg(message, length)
                                                : DecodeRos1LivoxCustomMsg(message, length));
  });
  return 0;
}

}  // namespace fusecal::fuzz
