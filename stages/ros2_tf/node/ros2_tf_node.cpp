#include "ros2_tf/node/ros2_tf_node.hpp"

#include <Eigen/Geometry>
#include <stdexcept>
#include <string>

#include "dds/dds.h"
#include "formats/conversions.hpp"
#include "ros2_dds/ros2_domain.hpp"
#include "ros2_messages.h"
#include "runtime/channels.hpp"

namespace fusecal {

Ros2TfNode::Ros2TfNode(const Ros2TfSettings& settings) : settings_(settings) {
  participant_ = JoinRos2Domain(settings_.domain, 4 << 20);
  const dds_entity_t topic =
      dds_create_topic(participant_, &tf2_msgs_msg_dds__TFMessage__desc, "rt/tf_static", nullptr, nullptr);
  if (topic < 0) throw std::runtime_error("ros2_tf: cannot create topic rt/tf_static: " + DdsErrorText(topic));
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  writer_ = dds_create_writer(participant_, topic, qos, nullptr);
  dds_delete_qos(qos);
  if (writer_ < 0) throw std::runtime_error("ros2_tf: cannot create the rt/tf_static writer: " + DdsErrorText(writer_));
}

Ros2TfNode::~Ros2TfNode() {
  if (participant_ > 0) dds_delete(participant_);
}

void Ros2TfNode::Start(Bus& bus) {
  subscriptions_.push_back(bus.Subscribe(typed_channels::kExtrinsic, [this](const extrinsic_t& e) { OnExtrinsic(e); }));
}

// T_camera_lidar maps points of the child frame (LiDAR) into the parent (camera): exactly tf's
// transform of child_frame_id in header.frame_id.
void Ros2TfNode::OnExtrinsic(const extrinsic_t& e) {
  if (e.version <= last_version_) return;  // a repeat (retry) of a version already published
  const Isometry3 T = FromRowMajor(e.T_camera_lidar);
  const Eigen::Quaterniond q(T.linear());
  geometry_msgs_msg_dds__TransformStamped_ transform{};
  transform.header_.stamp_.sec_ = static_cast<int32_t>(e.utime / 1000000);
  transform.header_.stamp_.nanosec_ = static_cast<uint32_t>((e.utime % 1000000) * 1000);
  transform.header_.frame_id_ = const_cast<char*>(settings_.parent_frame.c_str());
  transform.child_frame_id_ = const_cast<char*>(settings_.child_frame.c_str());
  transform.transform_.translation_ = {T.translation().x(), T.translation().y(), T.translation().z()};
  transform.transform_.rotation_ = {q.x(), q.y(), q.z(), q.w()};
  tf2_msgs_msg_dds__TFMessage_ message{};
  message.transforms_._maximum = message.transforms_._length = 1;
  message.transforms_._buffer = &transform;
  message.transforms_._release = false;
  if (const dds_return_t rc = dds_write(writer_, &message); rc < 0)
    throw std::runtime_error("ros2_tf: writing rt/tf_static failed: " + DdsErrorText(rc));
  last_version_ = e.version;
  ++published_;
}

StageStatus Ros2TfNode::Status() const {
  StageStatus s;
  s.state = published_ ? "publishing rt/tf_static" : "waiting for EXTRINSIC";
  s.counters = {{"published", published_}, {"version", last_version_}, {"domain", settings_.domain}};
  return s;
}

}  // namespace fusecal
