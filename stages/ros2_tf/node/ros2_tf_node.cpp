#include "stages/ros2_tf/node/ros2_tf_node.hpp"

#include <Eigen/Geometry>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "dds/dds.h"
#include "ros2_messages.h"
#include "runtime/channels.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/ros2_names.hpp"
#include "stages/formats/ros_sensor_encode.hpp"
#include "stages/ros2_dds/ros2_domain.hpp"
#include "stages/ros2_tf/node/ros2_views.hpp"

namespace fusecal {

namespace {
constexpr int64_t kDiagnosticsPeriodUs = 1000000;  // 1 Hz, as ROS 2's diagnostic_updater

dds_entity_t CreateTopic(dds_entity_t participant, const dds_topic_descriptor_t* descriptor,
                         const std::string& dds_topic) {
  const dds_entity_t topic = dds_create_topic(participant, descriptor, dds_topic.c_str(), nullptr, nullptr);
  if (topic < 0) throw std::runtime_error("ros2_tf: cannot create topic " + dds_topic + ": " + DdsErrorText(topic));
  return topic;
}

// Reliable or best effort, transient local or volatile, keep last `depth`; the caller deletes it.
dds_qos_t* CreateQos(bool reliable, bool transient_local, int depth) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, DDS_SECS(1));
  dds_qset_durability(qos, transient_local ? DDS_DURABILITY_TRANSIENT_LOCAL : DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, depth);
  return qos;
}
}  // namespace

Ros2TfNode::Ros2TfNode(const Ros2TfSettings& settings) : settings_(settings) {
  participant_ = JoinRos2Domain(settings_.domain, 4 << 20);
  writer_ = MakeWriter("rt/tf_static", &tf2_msgs_msg_dds__TFMessage__desc, true);
  if (!settings_.overlay_topic.empty())
    overlay_writer_ = MakeWriter(RosTopicToDds(settings_.overlay_topic), &sensor_msgs_msg_dds__Image__desc, true);
  if (settings_.diagnostics)
    diagnostics_writer_ = MakeWriter("rt/diagnostics", &diagnostic_msgs_msg_dds__DiagnosticArray__desc, false);
  tf_static_reader_ = MakeTreeReader("rt/tf_static", true);
  tf_reader_ = MakeTreeReader("rt/tf", false);
}

// tf2_ros's listeners: /tf_static reliable and transient local (a late joiner gets the tree), /tf best
// effort (matches every writer).
int Ros2TfNode::MakeTreeReader(const std::string& dds_topic, bool transient_local) {
  dds_qos_t* qos = CreateQos(transient_local, transient_local, 100);
  const dds_entity_t reader = dds_create_reader(
      participant_, CreateTopic(participant_, &tf2_msgs_msg_dds__TFMessage__desc, dds_topic), qos, nullptr);
  dds_delete_qos(qos);
  if (reader < 0)
    throw std::runtime_error("ros2_tf: cannot create the " + dds_topic + " reader: " + DdsErrorText(reader));
  return reader;
}

void Ros2TfNode::ReadTree() {
  constexpr int kBatch = 16;
  for (const dds_entity_t reader : {tf_static_reader_, tf_reader_}) {
    void* samples[kBatch] = {nullptr};
    dds_sample_info_t infos[kBatch];
    for (;;) {
      const dds_return_t n = dds_take(reader, samples, infos, kBatch, kBatch);
      if (n <= 0) break;
      for (int i = 0; i < n; ++i) {
        if (!infos[i].valid_data) continue;
        const auto* message = static_cast<const tf2_msgs_msg_dds__TFMessage_*>(samples[i]);
        for (uint32_t k = 0; k < message->transforms_._length; ++k) {
          const auto& t = message->transforms_._buffer[k];
          const std::string parent = t.header_.frame_id_ ? t.header_.frame_id_ : "";
          const std::string child = t.child_frame_id_ ? t.child_frame_id_ : "";
          if (parent == parent_name_ && child == child_name_) continue;  // ours
          frames_.Add(parent, child);
        }
      }
      dds_return_loan(reader, samples, n);
      if (n < kBatch) break;
    }
  }
}

// Reliable, depth 1; transient local (a late subscriber gets the latest) or volatile.
int Ros2TfNode::MakeWriter(const std::string& dds_topic, const void* descriptor, bool transient_local) {
  dds_qos_t* qos = CreateQos(true, transient_local, 1);
  const dds_entity_t writer = dds_create_writer(
      participant_, CreateTopic(participant_, static_cast<const dds_topic_descriptor_t*>(descriptor), dds_topic), qos,
      nullptr);
  dds_delete_qos(qos);
  if (writer < 0)
    throw std::runtime_error("ros2_tf: cannot create the " + dds_topic + " writer: " + DdsErrorText(writer));
  return writer;
}

Ros2TfNode::~Ros2TfNode() {
  if (participant_ > 0) dds_delete(participant_);
}

void Ros2TfNode::Start(Bus& bus) {
  subscriptions_.push_back(bus.Subscribe(channels::kExtrinsic, [this](const extrinsic_t& e) { OnExtrinsic(e); }));
  // Stations: the frames the sensors' headers name, and the overlay.
  subscriptions_.push_back(bus.Subscribe(channels::kStation, [this](const station_t& s) {
    if (!s.image.frame_id.empty()) header_parent_ = s.image.frame_id;
    if (!s.cloud.frame_id.empty()) header_child_ = s.cloud.frame_id;
    if (overlay_writer_ <= 0) return;
    station_ = std::make_unique<station_t>(s);
    PublishOverlay();
  }));
}

std::string Ros2TfNode::ParentFrame() const {
  return !settings_.parent_frame.empty() ? settings_.parent_frame : header_parent_;
}

std::string Ros2TfNode::ChildFrame() const {
  return !settings_.child_frame.empty() ? settings_.child_frame : header_child_;
}

void Ros2TfNode::Tick(Bus&, int64_t now_utime) {
  ReadTree();
  // A parent of the child frame learned after the calibration was published: publish it again under the
  // new name (late joiners then get that one).
  if (extrinsic_ && frames_.ChildName(ParentFrame(), ChildFrame()) != child_name_) WriteTransform(*extrinsic_);
  if (diagnostics_writer_ <= 0 || !latest_ || now_utime - last_diagnostics_utime_ < kDiagnosticsPeriodUs) return;
  last_diagnostics_utime_ = now_utime;
  PublishDiagnostics();
}

// T_camera_lidar maps points of the child frame (LiDAR) into the parent (camera): exactly tf's
// transform of child_frame_id in header.frame_id.
void Ros2TfNode::OnExtrinsic(const extrinsic_t& e) {
  if (e.version <= last_version_) return;  // a repeat (retry) of a version already published
  last_version_ = e.version;
  latest_ = std::make_unique<extrinsic_t>(e);
  if (e.status == extrinsic_t::STATUS_FAILED) {
    // No estimate (e.g. just after a change of the rig): tf_static keeps the one it has; the diagnostics say so.
    if (diagnostics_writer_ > 0) PublishDiagnostics();
    return;
  }
  ReadTree();
  WriteTransform(e);
  ++published_;
  extrinsic_ = std::make_unique<extrinsic_t>(e);
  PublishOverlay();
  if (diagnostics_writer_ > 0) PublishDiagnostics();
}

void Ros2TfNode::WriteTransform(const extrinsic_t& e) {
  const std::string parent = ParentFrame(), child = frames_.ChildName(parent, ChildFrame());
  if (child != child_name_ && child != ChildFrame())
    std::fprintf(stderr,
                 "ros2_tf: %s already has the parent %s on /tf or /tf_static; publishing the calibration as %s -> %s "
                 "so that the tree keeps one parent per frame\n",
                 ChildFrame().c_str(), frames_.OtherParent(parent, ChildFrame()).c_str(), parent.c_str(),
                 child.c_str());
  child_name_ = child;
  parent_name_ = parent;
  const Isometry3 T = FromRowMajor(e.T_camera_lidar);
  const Eigen::Quaterniond q(T.linear());
  geometry_msgs_msg_dds__TransformStamped_ transform{};
  transform.header_.stamp_.sec_ = static_cast<int32_t>(e.utime / 1000000);
  transform.header_.stamp_.nanosec_ = static_cast<uint32_t>((e.utime % 1000000) * 1000);
  transform.header_.frame_id_ = const_cast<char*>(parent_name_.c_str());
  transform.child_frame_id_ = const_cast<char*>(child_name_.c_str());
  transform.transform_.translation_ = {T.translation().x(), T.translation().y(), T.translation().z()};
  transform.transform_.rotation_ = {q.x(), q.y(), q.z(), q.w()};
  tf2_msgs_msg_dds__TFMessage_ message{};
  message.transforms_._maximum = message.transforms_._length = 1;
  message.transforms_._buffer = &transform;
  message.transforms_._release = false;
  if (const dds_return_t rc = dds_write(writer_, &message); rc < 0)
    throw std::runtime_error("ros2_tf: writing rt/tf_static failed: " + DdsErrorText(rc));
}

// The latest station through the latest extrinsic (nothing until both are there).
void Ros2TfNode::PublishOverlay() {
  if (overlay_writer_ <= 0 || !station_ || !extrinsic_) return;
  const auto camera = MakeCameraModel(CameraFromMsg(station_->camera));
  const RosImage image = ToRosImage(DrawPointsOnImage(ImageToMat(station_->image), CloudFromMsg(station_->cloud),
                                                      *camera, FromRowMajor(extrinsic_->T_camera_lidar)),
                                    RosHeader{UtimeToRosStamp(station_->utime), ParentFrame()});
  sensor_msgs_msg_dds__Image_ out{};
  out.header_.stamp_.sec_ = static_cast<int32_t>(image.header.stamp.sec);
  out.header_.stamp_.nanosec_ = image.header.stamp.nsec;
  out.header_.frame_id_ = const_cast<char*>(image.header.frame_id.c_str());
  out.height_ = image.height;
  out.width_ = image.width;
  out.encoding_ = const_cast<char*>(image.encoding.c_str());
  out.step_ = image.step;
  out.data_._maximum = out.data_._length = static_cast<uint32_t>(image.data.size());
  out.data_._buffer = const_cast<uint8_t*>(image.data.data());
  out.data_._release = false;
  if (const dds_return_t rc = dds_write(overlay_writer_, &out); rc < 0)
    throw std::runtime_error("ros2_tf: writing " + settings_.overlay_topic + " failed: " + DdsErrorText(rc));
  ++overlays_;
}

void Ros2TfNode::PublishDiagnostics() {
  const DiagnosticReport report = DescribeExtrinsic(*latest_, extrinsic_.get());
  std::vector<diagnostic_msgs_msg_dds__KeyValue_> values;
  for (const auto& [key, value] : report.values)
    values.push_back({const_cast<char*>(key.c_str()), const_cast<char*>(value.c_str())});
  diagnostic_msgs_msg_dds__DiagnosticStatus_ status{};
  status.level_ = report.level;
  status.name_ = const_cast<char*>("fusecal: camera-LiDAR extrinsic");
  status.message_ = const_cast<char*>(report.message.c_str());
  const std::string hardware_id = ParentFrame();
  status.hardware_id_ = const_cast<char*>(hardware_id.c_str());
  status.values_._maximum = status.values_._length = static_cast<uint32_t>(values.size());
  status.values_._buffer = values.data();
  status.values_._release = false;
  diagnostic_msgs_msg_dds__DiagnosticArray_ array{};
  const RosTime stamp = UtimeToRosStamp(latest_->utime);
  array.header_.stamp_.sec_ = static_cast<int32_t>(stamp.sec);
  array.header_.stamp_.nanosec_ = stamp.nsec;
  array.header_.frame_id_ = const_cast<char*>("");
  array.status_._maximum = array.status_._length = 1;
  array.status_._buffer = &status;
  array.status_._release = false;
  if (const dds_return_t rc = dds_write(diagnostics_writer_, &array); rc < 0)
    throw std::runtime_error("ros2_tf: writing rt/diagnostics failed: " + DdsErrorText(rc));
  ++diagnostics_;
}

StageStatus Ros2TfNode::Status() const {
  StageStatus s;
  s.state = published_ ? "publishing rt/tf_static: " + parent_name_ + " -> " + child_name_ : "waiting for EXTRINSIC";
  s.counters = {{"published", published_},
                {"version", last_version_},
                {"domain", settings_.domain},
                {"overlays", overlays_},
                {"diagnostics", diagnostics_}};
  return s;
}

}  // namespace fusecal
