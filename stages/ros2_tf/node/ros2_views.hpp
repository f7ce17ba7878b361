// What fusecal-ros2-tf shows a ROS 2 user besides the transform, without DDS: the latest station's image
// with its LiDAR points drawn through the current extrinsic (for sensor_msgs/Image: rviz, Foxglove,
// rqt_image_view), and the calibration's state as one diagnostic_msgs/DiagnosticStatus (rqt's runtime
// monitor, Foxglove's diagnostics panel).
#pragma once

#include <cstdint>
#include <map>
#include <opencv2/core.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "fusecal/extrinsic_t.hpp"
#include "stages/foundation/camera_model.hpp"
#include "stages/foundation/point_cloud.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal {

// BGR copy of `image` (grey images turned to colour) with each LiDAR point that projects into it drawn
// as a dot coloured by its depth (near red, far blue, as the overlays of `calibrate`).
cv::Mat DrawPointsOnImage(const cv::Mat& image, const PointCloud& cloud, const CameraModel& camera,
                          const Isometry3& T_camera_lidar);

struct DiagnosticReport {
  uint8_t level = 0;  // diagnostic_msgs/DiagnosticStatus: 0 OK, 1 WARN, 2 ERROR
  std::string message;
  std::vector<std::pair<std::string, std::string>> values;
};

// OK when converged, WARN while refining or not converged, ERROR when degenerate or failed; the message
// is the verdict; the values are the version, the estimate, its standard deviations and the motions.
// A failed version has no estimate: with `held` (the version tf_static still holds) the values are held's
// and the level WARN, since the robot keeps a transform; without one, ERROR.
DiagnosticReport DescribeExtrinsic(const extrinsic_t& extrinsic, const extrinsic_t* held = nullptr);

// The parents other publishers give each frame on /tf and /tf_static (child -> parents).
class FrameParents {
 public:
  // A transform parent -> child seen on the domain (a leading '/' is dropped, as tf2 does).
  void Add(const std::string& parent, const std::string& child);
  // The name to publish the calibrated child under: `child` when it has no parent but `parent` (ours),
  // else `child` + "_calibrated", so that the robot's tree keeps one parent per frame.
  std::string ChildName(const std::string& parent, const std::string& child) const;
  // The first parent other than `parent` that `child` has, or "".
  std::string OtherParent(const std::string& parent, const std::string& child) const;

 private:
  std::map<std::string, std::set<std::string>> parents_;
};

}  // namespace fusecal
