#include "ros2_fastdds_types.hpp"

#include <utility>

namespace fusecal::fastdds_peer {
namespace {

std_msgs::msg::dds_::Header_ ToFastDds(RosHeader&& in) {
  std_msgs::msg::dds_::Header_ out;
  out.stamp_().sec_(static_cast<int32_t>(in.stamp.sec));
  out.stamp_().nanosec_(in.stamp.nsec);
  out.frame_id_(std::move(in.frame_id));
  return out;
}

}  // namespace

ros_sensor::Image_ ToFastDds(RosImage&& in) {
  ros_sensor::Image_ out;
  out.header_(ToFastDds(std::move(in.header)));
  out.height_(in.height);
  out.width_(in.width);
  out.encoding_(std::move(in.encoding));
  out.is_bigendian_(in.is_bigendian);
  out.step_(in.step);
  out.data_(std::move(in.data));
  return out;
}

ros_sensor::CompressedImage_ ToFastDds(RosCompressedImage&& in) {
  ros_sensor::CompressedImage_ out;
  out.header_(ToFastDds(std::move(in.header)));
  out.format_(std::move(in.format));
  out.data_(std::move(in.data));
  return out;
}

ros_sensor::PointCloud2_ ToFastDds(RosPointCloud2&& in) {
  ros_sensor::PointCloud2_ out;
  out.header_(ToFastDds(std::move(in.header)));
  out.height_(in.height);
  out.width_(in.width);
  for (RosPointField& f : in.fields) {
    ros_sensor::PointField_ field;
    field.name_(std::move(f.name));
    field.offset_(f.offset);
    field.datatype_(f.datatype);
    field.count_(f.count);
    out.fields_().push_back(std::move(field));
  }
  out.is_bigendian_(in.is_bigendian);
  out.point_step_(in.point_step);
  out.row_step_(in.row_step);
  out.data_(std::move(in.data));
  out.is_dense_(in.is_dense);
  return out;
}

ros_sensor::CameraInfo_ ToFastDds(RosCameraInfo&& in) {
  ros_sensor::CameraInfo_ out;
  out.header_(ToFastDds(std::move(in.header)));
  out.height_(in.height);
  out.width_(in.width);
  out.distortion_model_(std::move(in.distortion_model));
  out.d_(std::move(in.D));
  out.k_(in.K);
  out.r_(in.R);
  out.p_(in.P);
  out.binning_x_(in.binning_x);
  out.binning_y_(in.binning_y);
  out.roi_().x_offset_(in.roi.x_offset);
  out.roi_().y_offset_(in.roi.y_offset);
  out.roi_().height_(in.roi.height);
  out.roi_().width_(in.roi.width);
  out.roi_().do_rectify_(in.roi.do_rectify);
  return out;
}

livox_ros_driver2::msg::dds_::CustomMsg_ ToFastDds(RosLivoxCustomMsg&& in) {
  livox_ros_driver2::msg::dds_::CustomMsg_ out;
  out.header_(ToFastDds(std::move(in.header)));
  out.timebase_(in.timebase);
  out.point_num_(in.point_num);
  out.lidar_id_(in.lidar_id);
  out.rsvd_(in.rsvd);
  out.points_().reserve(in.points.size());
  for (const RosLivoxPoint& p : in.points) {
    livox_ros_driver2::msg::dds_::CustomPoint_ point;
    point.offset_time_(p.offset_time);
    point.x_(p.x);
    point.y_(p.y);
    point.z_(p.z);
    point.reflectivity_(p.reflectivity);
    point.tag_(p.tag);
    point.line_(p.line);
    out.points_().push_back(point);
  }
  return out;
}

}  // namespace fusecal::fastdds_peer
