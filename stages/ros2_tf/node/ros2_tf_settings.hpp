// Settings of fusecal-ros2-tf (section `ros2_tf` of the pipeline config).
#pragma once

#include <string>

#include "runtime/config_reader.hpp"

namespace fusecal {

struct Ros2TfSettings {
  bool enabled = false;  // `fusecal run` starts fusecal-ros2-tf with the stages
  int domain = 0;        // the ROS 2 domain (ROS_DOMAIN_ID)
  // header.frame_id: T_camera_lidar maps the child into it; empty: the image headers' frame (the camera's
  // optical frame), else "camera".
  std::string parent_frame;
  std::string child_frame;  // child_frame_id; empty: the cloud headers' frame, else "lidar"

  // The latest station's image with the LiDAR points drawn through the current extrinsic, as a
  // sensor_msgs/Image on this ROS 2 topic (empty: not published).
  std::string overlay_topic = "/fusecal/overlay";
  bool diagnostics = true;  // the calibration's state as a diagnostic_msgs/DiagnosticArray on /diagnostics

  // Empty when usable, else what is wrong: domain in [0, 232]; two different frame ids when both set; an
  // overlay topic ROS allows.
  std::string Validate() const;
};

Ros2TfSettings ReadRos2TfSettings(ConfigReader section);

}  // namespace fusecal
