// fusecal-ros2-tf: ROS 2 without ROS. Every EXTRINSIC becomes a tf2_msgs/TFMessage on the DDS topic
// `rt/tf_static` (reliable, transient local, depth 1, as tf2_ros's static broadcaster does), so a ROS 2
// system on the same domain sees parent_frame -> child_frame (T_camera_lidar) with no bridge; frames the
// config does not name are the ones in the headers of the sensors' messages (via STATION). For the
// user watching in rviz, Foxglove or rqt: the latest STATION's image with its points drawn through the
// latest extrinsic as a sensor_msgs/Image on `overlay_topic` (reliable, transient local, depth 1), and
// the calibration's state as a diagnostic_msgs/DiagnosticArray on `rt/diagnostics` (1 Hz). The types
// are generated from stages/ros2_dds/ros2_messages.idl (rosidl's form) by Cyclone's idlc.
// A robot's tree already gives its LiDAR frame a parent (base_link -> lidar_link on /tf_static or /tf):
// a second parent breaks tf2, so the node reads both topics and then publishes the calibration as
// parent_frame -> <child_frame>_calibrated, and says so in its log and STATUS.
#pragma once

#include <memory>
#include <vector>

#include "fusecal/extrinsic_t.hpp"
#include "fusecal/station_t.hpp"
#include "runtime/stage_main.hpp"
#include "stages/ros2_tf/node/ros2_tf_settings.hpp"
#include "stages/ros2_tf/node/ros2_views.hpp"

namespace fusecal {

class Ros2TfNode : public StageNode {
 public:
  // Throws std::runtime_error when the DDS participant, topic or writer cannot be made.
  explicit Ros2TfNode(const Ros2TfSettings& settings);
  ~Ros2TfNode() override;
  void Start(Bus& bus) override;
  void Tick(Bus& bus, int64_t now_utime) override;
  StageStatus Status() const override;

 private:
  void OnExtrinsic(const extrinsic_t& extrinsic);
  // Writes `extrinsic` on rt/tf_static, under the child name the known tree allows.
  void WriteTransform(const extrinsic_t& extrinsic);
  // Takes what other publishers sent on rt/tf_static and rt/tf into frames_.
  void ReadTree();
  // The camera's and the LiDAR's frame: the config's, else the ones the sensors' messages name.
  std::string ParentFrame() const;
  std::string ChildFrame() const;
  int MakeTreeReader(const std::string& dds_topic, bool transient_local);
  void PublishOverlay();
  void PublishDiagnostics();
  int MakeWriter(const std::string& dds_topic, const void* descriptor, bool transient_local);

  Ros2TfSettings settings_;
  int participant_ = 0, writer_ = 0;  // dds_entity_t
  int overlay_writer_ = 0, diagnostics_writer_ = 0;
  std::unique_ptr<station_t> station_;      // the latest, for the overlay
  std::unique_ptr<extrinsic_t> extrinsic_;  // the latest published
  std::unique_ptr<extrinsic_t> latest_;     // the latest received (a failed one is not published)
  int64_t last_diagnostics_utime_ = 0;
  int overlays_ = 0, diagnostics_ = 0;
  std::vector<Subscription> subscriptions_;
  int tf_static_reader_ = 0, tf_reader_ = 0;  // dds_entity_t
  FrameParents frames_;
  std::string parent_name_, child_name_;                           // the frames the calibration was last published with
  std::string header_parent_ = "camera", header_child_ = "lidar";  // as the stations' messages name them
  int published_ = 0;
  int last_version_ = -1;
};

}  // namespace fusecal
