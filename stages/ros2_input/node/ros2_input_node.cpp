#include "stages/ros2_input/node/ros2_input_node.hpp"

#include <dds/ddsi/ddsi_serdata.h>

#include <chrono>
#include <iostream>
#include <stdexcept>

#include "ros2_messages.h"
#include "runtime/channels.hpp"
#include "stages/formats/camera_file.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/ros2_dds/ros2_domain.hpp"

namespace fusecal {

namespace {

constexpr int kTakeBatch = 8;
// CAMERA_INFO is state: sent again every second, so that a stage started later (or restarted) has it
// before its first station (with 5 s, a stationarity stage that came up after the first one dropped its
// first two stations for want of it).
constexpr int64_t kCameraInfoRepeatUs = 1000000;

const dds_topic_descriptor_t* DescriptorOf(Ros2SensorTopic kind) {
  switch (kind) {
    case Ros2SensorTopic::kCameraInfo:
      return &sensor_msgs_msg_dds__CameraInfo__desc;
    case Ros2SensorTopic::kImage:
      return &sensor_msgs_msg_dds__Image__desc;
    case Ros2SensorTopic::kCompressedImage:
      return &sensor_msgs_msg_dds__CompressedImage__desc;
    case Ros2SensorTopic::kCloud:
      return &sensor_msgs_msg_dds__PointCloud2__desc;
    case Ros2SensorTopic::kLivoxCloud:
      return &livox_ros_driver2_msg_dds__CustomMsg__desc;
  }
  return nullptr;
}

int64_t WallUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

Ros2InputNode::Ros2InputNode(const Ros2InputSettings& settings) : settings_(settings) {
  if (const std::string problem = settings_.RigProblem(); !problem.empty())
    throw std::runtime_error("ros2_input." + problem);
  const std::vector<Ros2CameraTopics> topics = settings_.CameraTopics();
  for (const Ros2CameraTopics& c : topics) {
    std::optional<CameraParams> camera;
    if (!c.camera_file.empty()) camera = LoadCameraFile(c.camera_file);
    cameras_.push_back({c.name, std::make_unique<Ros2SensorInput>(camera)});
  }
  cloud_input_ = std::make_unique<Ros2SensorInput>();
  participant_ = JoinRos2Domain(settings_.domain, ReceiveBufferBytes(settings_));
  discovery_ = std::make_unique<Ros2Discovery>(participant_);
  for (size_t k = 0; k < topics.size(); ++k)
    readers_.push_back({topics[k].compressed() ? Ros2SensorTopic::kCompressedImage : Ros2SensorTopic::kImage,
                        topics[k].image_topic, static_cast<int>(k)});
  readers_.push_back(
      {settings_.livox() ? Ros2SensorTopic::kLivoxCloud : Ros2SensorTopic::kCloud, settings_.cloud_topic, -1});
  for (size_t k = 0; k < topics.size(); ++k)
    if (topics[k].camera_file.empty())
      readers_.push_back({Ros2SensorTopic::kCameraInfo, topics[k].CameraInfoTopic(), static_cast<int>(k)});
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, settings_.depth);
  for (Reader& r : readers_) {
    const std::string dds_name = RosTopicToDds(r.topic);
    const dds_entity_t topic = dds_create_topic(participant_, DescriptorOf(r.kind), dds_name.c_str(), nullptr, nullptr);
    if (topic < 0) {
      dds_delete_qos(qos);
      throw std::runtime_error("ros2_input: cannot create topic " + dds_name + ": " + DdsErrorText(topic));
    }
    r.reader = dds_create_reader(participant_, topic, qos, nullptr);
    if (r.reader < 0) {
      dds_delete_qos(qos);
      throw std::runtime_error("ros2_input: cannot create the reader of " + dds_name + ": " + DdsErrorText(r.reader));
    }
  }
  dds_delete_qos(qos);
}

Ros2InputNode::~Ros2InputNode() {
  if (participant_ > 0) dds_delete(participant_);
}

void Ros2InputNode::Start(Bus& bus) {
  start_utime_ = WallUtime();
  std::cerr << "fusecal-ros2_input: listening on ROS 2 domain " << settings_.domain << ":";
  for (const Reader& r : readers_)
    std::cerr << " " << r.topic << " (" << Ros2TypeOf(r.kind)
              << (r.camera >= 0 && !cameras_[r.camera].name.empty() ? ", camera " + cameras_[r.camera].name : "")
              << ")";
  std::cerr << std::endl;
  for (size_t k = 0; k < cameras_.size(); ++k)
    if (cameras_[k].input->camera())
      Publish(bus, Ros2InputFrame{cameras_[k].input->camera(), {}, {}, {}}, static_cast<int>(k));
}

void Ros2InputNode::Tick(Bus& bus, int64_t) {
  const int64_t now = WallUtime();
  for (Reader& r : readers_) TakeAll(bus, r, now);
  for (size_t k = 0; k < cameras_.size(); ++k)
    if (cameras_[k].input->camera() && now - cameras_[k].last_camera_info_utime > kCameraInfoRepeatUs)
      Publish(bus, Ros2InputFrame{cameras_[k].input->camera(), {}, {}, {}}, static_cast<int>(k));
  CheckTopicsArrived(now);
}

Ros2SensorInput& Ros2InputNode::InputOf(const Reader& r) const {
  return r.camera < 0 ? *cloud_input_ : *cameras_[r.camera].input;
}

std::string Ros2InputNode::CounterKey(const Reader& r) const {
  const std::string key = r.kind == Ros2SensorTopic::kCloud || r.kind == Ros2SensorTopic::kLivoxCloud ? "cloud"
                          : r.kind == Ros2SensorTopic::kCameraInfo                                    ? "camera_info"
                                                                                                      : "image";
  return r.camera < 0 || cameras_[r.camera].name.empty() ? key : key + "_" + cameras_[r.camera].name;
}

// Every sample the reader holds, as serialized CDR (the encapsulation header first).
void Ros2InputNode::TakeAll(Bus& bus, Reader& r, int64_t now_utime) {
  for (;;) {
    ddsi_serdata* samples[kTakeBatch] = {};
    dds_sample_info_t infos[kTakeBatch];
    const dds_return_t n = dds_takecdr(r.reader, samples, kTakeBatch, infos, DDS_ANY_STATE);
    if (n < 0) throw std::runtime_error("ros2_input: taking from " + r.topic + " failed: " + DdsErrorText(n));
    for (int i = 0; i < n; ++i) {
      if (infos[i].valid_data) {
        const uint32_t size = ddsi_serdata_size(samples[i]);
        buffer_.resize(size);
        ddsi_serdata_to_ser(samples[i], 0, size, buffer_.data());
        const double latency_s = (now_utime * 1000.0 - static_cast<double>(infos[i].source_timestamp)) * 1e-9;
        if (latency_s >= 0 && latency_s < 3600) {
          r.latency_sum_s += latency_s;
          r.latency_max_s = std::max(r.latency_max_s, latency_s);
          ++r.latency_count;
        }
        const auto start = std::chrono::steady_clock::now();
        const Ros2InputFrame frame = InputOf(r).Take(r.kind, buffer_.data(), buffer_.size(), now_utime);
        if (!frame.error.empty() && !r.warned) {
          r.warned = true;
          std::cerr << "fusecal-ros2_input: " << r.topic << ": skipped a message: " << frame.error
                    << " (counted as malformed in STATUS; later ones are not printed)" << std::endl;
        }
        Publish(bus, frame, r.camera);
        work_.Add(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      }
      ddsi_serdata_unref(samples[i]);
    }
    if (n < kTakeBatch) return;
  }
}

void Ros2InputNode::Publish(Bus& bus, const Ros2InputFrame& frame, int camera) {
  const std::string name = camera < 0 ? "" : cameras_[camera].name;
  if (frame.camera && camera >= 0) {
    camera_info_t info = CameraToMsg(*frame.camera, WallUtime());
    info.name = name;
    bus.Publish(ForCamera(channels::kCameraInfo, name), info);
    cameras_[camera].last_camera_info_utime = WallUtime();
  }
  if (frame.image) {
    const SensorImage& image = *frame.image;
    const std::string frame_id = image.frame_id.empty() ? (name.empty() ? "camera" : name) : image.frame_id;
    if (image.encoded.empty()) {
      bus.Publish(ForCamera(channels::kCameraImage, name),
                  MatToImage(image.pixels, image.pixels.channels() == 1 ? "mono8" : "bgr8", image.utime, frame_id));
    } else {
      image_t msg{};
      msg.utime = image.utime;
      msg.frame_id = frame_id;
      msg.width = image.width;
      msg.height = image.height;
      msg.encoding = image.encoding;
      msg.data = image.encoded;
      msg.size = static_cast<int32_t>(image.encoded.size());
      bus.Publish(ForCamera(channels::kCameraImage, name), msg);
    }
    ++published_images_;
    first_stamp_ = std::min(first_stamp_, image.utime);
    last_stamp_ = std::max(last_stamp_, image.utime);
  }
  if (frame.scan) {
    bus.Publish(channels::kLidarScan, CloudToMsg(frame.scan->cloud, frame.scan->utime,
                                                 frame.scan->frame_id.empty() ? "lidar" : frame.scan->frame_id));
    ++published_scans_;
    first_stamp_ = std::min(first_stamp_, frame.scan->utime);
    last_stamp_ = std::max(last_stamp_, frame.scan->utime);
  }
}

void Ros2InputNode::CheckTopicsArrived(int64_t now_utime) {
  if (no_input_ || now_utime - start_utime_ < static_cast<int64_t>(settings_.topic_timeout_s * 1e6)) return;
  std::vector<const Reader*> missing;
  for (const Reader& r : readers_)
    if (InputOf(r).counts(r.kind).received == 0) missing.push_back(&r);
  if (missing.empty()) return;
  no_input_ = true;
  throw std::runtime_error(MissingTopicsMessage(missing));
}

std::string Ros2InputNode::MissingTopicsMessage(const std::vector<const Reader*>& missing) const {
  std::string text = "no message in " + std::to_string(static_cast<int>(settings_.topic_timeout_s)) +
                     " s on ROS 2 domain " + std::to_string(settings_.domain) + " on";
  for (size_t i = 0; i < missing.size(); ++i)
    text += std::string(i ? ", " : " ") + missing[i]->topic + " (" + Ros2TypeOf(missing[i]->kind) + ")";
  std::string seen;
  for (const Ros2TopicSeen& t : discovery_->Publications())
    if (t.topic.rfind("/", 0) == 0) seen += (seen.empty() ? "" : ", ") + t.topic + " (" + t.type + ")";
  if (seen.empty())
    return text +
           "; no ROS 2 publisher is seen on this domain: check ROS_DOMAIN_ID (ros2_input.domain), that the "
           "robot is on this network, and that multicast discovery reaches this host";
  return text + "; the domain has: " + seen +
         ". Set ros2_input.image_topic, cloud_topic and camera_info_topic (or camera_file) to topics listed here";
}

StageStatus Ros2InputNode::Status() const {
  StageStatus s;
  long received = 0;
  for (const Reader& r : readers_) received += InputOf(r).counts(r.kind).received;
  s.state = no_input_ ? "no_input" : received == 0 ? "waiting for topics" : "receiving";
  s.counters["images"] = static_cast<double>(published_images_);
  s.counters["scans"] = static_cast<double>(published_scans_);
  int unstamped = cloud_input_->unstamped();
  for (const auto& c : cameras_) unstamped += c.input->unstamped();
  s.counters["unstamped"] = unstamped;
  if (last_stamp_ > first_stamp_) s.counters["stream_span_s"] = (last_stamp_ - first_stamp_) * 1e-6;
  work_.AddTo(&s.counters);
  for (const Reader& r : readers_) {
    const Ros2TopicCounts& c = InputOf(r).counts(r.kind);
    const std::string key = CounterKey(r);
    s.counters[key + "_received"] = static_cast<double>(c.received);
    s.counters[key + "_malformed"] = static_cast<double>(c.malformed);
    s.counters[key + "_lost"] = static_cast<double>(c.lost);
    s.counters[key + "_mb"] = static_cast<double>(c.bytes) / 1e6;
    if (r.latency_count > 0) {
      s.counters[key + "_latency_mean_s"] = r.latency_sum_s / static_cast<double>(r.latency_count);
      s.counters[key + "_latency_max_s"] = r.latency_max_s;
    }
  }
  return s;
}

}  // namespace fusecal
