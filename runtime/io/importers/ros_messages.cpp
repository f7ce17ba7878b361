#include "runtime/io/importers/ros_messages.hpp"

#include <algorithm>
#include <utility>

namespace fusecal {

namespace {

RosHeader ToHeader(std_msgs::Header header) { return RosHeader{FromRos1(header.stamp), std::move(header.frame_id)}; }

}  // namespace

RosTime FromRos1(const ros::Time& time) { return RosTime{time.sec, time.nsec}; }

RosImage FromRos1(sensor_msgs::Image msg) {
  RosImage out;
  out.header = ToHeader(std::move(msg.header));
  out.height = msg.height;
  out.width = msg.width;
  out.encoding = std::move(msg.encoding);
  out.is_bigendian = msg.is_bigendian;
  out.step = msg.step;
  out.data = std::move(msg.data);
  return out;
}

RosCompressedImage FromRos1(sensor_msgs::CompressedImage msg) {
  RosCompressedImage out;
  out.header = ToHeader(std::move(msg.header));
  out.format = std::move(msg.format);
  out.data = std::move(msg.data);
  return out;
}

RosPointCloud2 FromRos1(sensor_msgs::PointCloud2 msg) {
  RosPointCloud2 out;
  out.header = ToHeader(std::move(msg.header));
  out.height = msg.height;
  out.width = msg.width;
  for (auto& field : msg.fields)
    out.fields.push_back(RosPointField{std::move(field.name), field.offset, field.datatype, field.count});
  out.is_bigendian = msg.is_bigendian != 0;
  out.point_step = msg.point_step;
  out.row_step = msg.row_step;
  out.data = std::move(msg.data);
  out.is_dense = msg.is_dense != 0;
  return out;
}

RosCameraInfo FromRos1(sensor_msgs::CameraInfo msg) {
  RosCameraInfo out;
  out.header = ToHeader(std::move(msg.header));
  out.height = msg.height;
  out.width = msg.width;
  out.distortion_model = std::move(msg.distortion_model);
  out.D = std::move(msg.D);
  std::copy(msg.K.begin(), msg.K.end(), out.K.begin());
  std::copy(msg.R.begin(), msg.R.end(), out.R.begin());
  std::copy(msg.P.begin(), msg.P.end(), out.P.begin());
  out.binning_x = msg.binning_x;
  out.binning_y = msg.binning_y;
  out.roi =
      RosRegionOfInterest{msg.roi.x_offset, msg.roi.y_offset, msg.roi.height, msg.roi.width, msg.roi.do_rectify != 0};
  return out;
}

}  // namespace fusecal
