#include "tests/support/ros1_bag_writer.hpp"

#include <rosbag/bag.h>

#include <algorithm>

namespace fusecal::testing {

std_msgs::Header ToRos1(const RosHeader& header) {
  std_msgs::Header out;
  out.stamp = ros::Time(static_cast<uint32_t>(header.stamp.sec), header.stamp.nsec);
  out.frame_id = header.frame_id;
  return out;
}

sensor_msgs::Image ToRos1(const RosImage& msg) {
  sensor_msgs::Image out;
  out.header = ToRos1(msg.header);
  out.height = msg.height;
  out.width = msg.width;
  out.encoding = msg.encoding;
  out.is_bigendian = msg.is_bigendian;
  out.step = msg.step;
  out.data = msg.data;
  return out;
}

sensor_msgs::CompressedImage ToRos1(const RosCompressedImage& msg) {
  sensor_msgs::CompressedImage out;
  out.header = ToRos1(msg.header);
  out.format = msg.format;
  out.data = msg.data;
  return out;
}

sensor_msgs::PointCloud2 ToRos1(const RosPointCloud2& msg) {
  sensor_msgs::PointCloud2 out;
  out.header = ToRos1(msg.header);
  out.height = msg.height;
  out.width = msg.width;
  for (const RosPointField& field : msg.fields) {
    sensor_msgs::PointField f;
    f.name = field.name;
    f.offset = field.offset;
    f.datatype = field.datatype;
    f.count = field.count;
    out.fields.push_back(f);
  }
  out.is_bigendian = msg.is_bigendian;
  out.point_step = msg.point_step;
  out.row_step = msg.row_step;
  out.data = msg.data;
  out.is_dense = msg.is_dense;
  return out;
}

sensor_msgs::CameraInfo ToRos1(const RosCameraInfo& msg) {
  sensor_msgs::CameraInfo out;
  out.header = ToRos1(msg.header);
  out.height = msg.height;
  out.width = msg.width;
  out.distortion_model = msg.distortion_model;
  out.D = msg.D;
  std::copy(msg.K.begin(), msg.K.end(), out.K.begin());
  std::copy(msg.R.begin(), msg.R.end(), out.R.begin());
  std::copy(msg.P.begin(), msg.P.end(), out.P.begin());
  out.binning_x = msg.binning_x;
  out.binning_y = msg.binning_y;
  return out;
}

void WriteRos1Bag(const std::string& path, const std::vector<RecordedMessage>& recording) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  for (const RecordedMessage& r : recording) {
    const ros::Time arrival(static_cast<uint32_t>(r.arrival_utime / 1000000),
                            static_cast<uint32_t>(r.arrival_utime % 1000000) * 1000);
    std::visit([&](const auto& msg) { bag.write(r.topic, arrival, ToRos1(msg)); }, r.msg);
  }
}

}  // namespace fusecal::testing
