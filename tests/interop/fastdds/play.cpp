// `play`: a recording published as a ROS 2 camera and LiDAR driver on Fast DDS would publish it.
#include <chrono>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <stdexcept>
#include <thread>

#include "fastdds_domain.hpp"
#include "fastdds_generated/ros2_messagesPubSubTypes.h"
#include "fusecal/camera_info_t.hpp"
#include "fusecal/image_t.hpp"
#include "fusecal/point_cloud_t.hpp"
#include "peer_commands.hpp"
#include "ros2_fastdds_types.hpp"
#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/ros_sensor_encode.hpp"
#include "tests/support/looped_recording.hpp"

namespace fusecal::fastdds_peer {
namespace {

using Clock = std::chrono::steady_clock;

struct Stream {
  std::string topic;  // the ROS name
  dds::DataWriter* writer = nullptr;
  long sent = 0;
};

// One camera of the log: its channels and its two topics.
struct CameraStreams {
  std::string name;  // "" for the log's one camera (CAMERA_IMAGE, CAMERA_INFO)
  Stream info, image;
  std::optional<CameraParams> camera;  // from the log's CAMERA_INFO(_<name>)
};

class Player {
 public:
  Player(FastDdsDomain& domain, const PlayOptions& options) : compressed_(options.compressed), livox_(options.livox) {
    const dds::DataWriterQos qos = SensorWriterQos(!options.best_effort);
    std::vector<std::pair<std::string, std::pair<std::string, std::string>>> cameras;  // name, (image, info) topics
    if (options.rig_cameras.empty()) cameras.push_back({"", {options.image_topic, options.camera_info_topic}});
    for (const auto& name : options.rig_cameras)
      cameras.push_back({name, {"/" + name + "/image_raw", "/" + name + "/camera_info"}});
    for (const auto& [name, topics] : cameras) {
      CameraStreams c;
      c.name = name;
      c.info = Make<ros_sensor::CameraInfo_PubSubType>(domain, topics.second, qos);
      if (compressed_)
        c.image = Make<ros_sensor::CompressedImage_PubSubType>(domain, topics.first + "/compressed", qos);
      else
        c.image = Make<ros_sensor::Image_PubSubType>(domain, topics.first, qos);
      cameras_.push_back(std::move(c));
    }
    if (livox_)
      cloud_ = Make<livox_ros_driver2::msg::dds_::CustomMsg_PubSubType>(domain, options.cloud_topic, qos);
    else
      cloud_ = Make<ros_sensor::PointCloud2_PubSubType>(domain, options.cloud_topic, qos);
  }

  // True once every writer has a matched reader; else false after `seconds`, with the topics that have
  // none in `missing`.
  bool WaitForReaders(double seconds, std::string* missing) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    for (;;) {
      missing->clear();
      for (const Stream* s : Streams()) {
        dds::PublicationMatchedStatus status;
        s->writer->get_publication_matched_status(status);
        if (status.current_count == 0) *missing += (missing->empty() ? "" : ", ") + s->topic;
      }
      if (missing->empty()) return true;
      if (Clock::now() > end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }

  void Send(const LogEvent& event) {
    const int size = static_cast<int>(event.data.size());
    for (CameraStreams& c : cameras_) {
      // The camera model goes out beside every image, stamped like it, as camera drivers publish it.
      if (event.channel == ForCamera(channels::kCameraInfo, c.name).name) {
        camera_info_t msg{};
        if (msg.decode(event.data.data(), 0, size) >= 0) c.camera = CameraFromMsg(msg);
      } else if (event.channel == ForCamera(channels::kCameraImage, c.name).name) {
        image_t msg{};
        if (msg.decode(event.data.data(), 0, size) < 0) return;
        const std::string frame = c.name.empty() ? "camera" : c.name;
        if (c.camera) {
          auto info = ToFastDds(ToRosCameraInfo(*c.camera, RosHeader{UtimeToRosStamp(msg.utime), frame}));
          Write(c.info, &info);
        }
        SendImage(c, msg, frame);
      }
    }
    if (event.channel == channels::kLidarScan.name) {
      point_cloud_t msg{};
      if (msg.decode(event.data.data(), 0, size) >= 0) SendCloud(msg);
    }
  }

  // Waits, at most `seconds` in all, until the reliable readers have acknowledged every sample; the
  // topics that still have unacknowledged samples go to `late`.
  bool WaitForAcknowledgments(double seconds, std::string* late) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    late->clear();
    for (const Stream* s : Streams()) {
      const double left = std::max(0.0, std::chrono::duration<double>(end - Clock::now()).count());
      if (s->writer->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(left)) !=
          eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK)
        *late += (late->empty() ? "" : ", ") + s->topic;
    }
    return late->empty();
  }

  std::string Json() const {
    std::string text = "{";
    for (const Stream* s : Streams())
      text += std::string(text.size() > 1 ? ", " : "") + "\"" + s->topic + "\": " + std::to_string(s->sent);
    return text + "}";
  }

 private:
  template <typename PubSubType>
  static Stream Make(FastDdsDomain& domain, const std::string& topic, const dds::DataWriterQos& qos) {
    return Stream{topic, domain.Writer(domain.Topic<PubSubType>(topic), qos), 0};
  }

  void SendCloud(const point_cloud_t& msg) {
    const RosHeader header{UtimeToRosStamp(msg.utime), "lidar"};
    if (livox_) {
      auto out = ToFastDds(ToRosLivoxCustomMsg(CloudFromMsg(msg), header));
      Write(cloud_, &out);
    } else {
      auto out = ToFastDds(ToRosPointCloud2(CloudFromMsg(msg), header));
      Write(cloud_, &out);
    }
  }

  void SendImage(CameraStreams& c, const image_t& msg, const std::string& frame) {
    const RosHeader header{UtimeToRosStamp(msg.utime), frame};
    if (!compressed_) {
      auto out = ToFastDds(ToRosImage(ImageToMat(msg), header));
      Write(c.image, &out);
      return;
    }
    // jpeg and png pass through as they are; raw images become png (lossless).
    std::vector<uint8_t> bytes = msg.data;
    std::string encoding = msg.encoding;
    if (encoding != "jpeg" && encoding != "png") {
      cv::imencode(".png", ImageToMat(msg), bytes);
      encoding = "png";
    }
    auto out = ToFastDds(ToRosCompressedImage(bytes, encoding, header));
    Write(c.image, &out);
  }

  std::vector<const Stream*> Streams() const {
    std::vector<const Stream*> streams;
    for (const CameraStreams& c : cameras_) streams.insert(streams.end(), {&c.info, &c.image});
    streams.push_back(&cloud_);
    return streams;
  }

  static void Write(Stream& s, void* sample) {
    if (!s.writer->write(sample)) throw std::runtime_error("writing " + s.topic + " failed");
    ++s.sent;
  }

  bool compressed_, livox_;
  std::vector<CameraStreams> cameras_;
  Stream cloud_;
};

double UnixNowS() { return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count(); }

}  // namespace

int Play(const PlayOptions& options) {
  testing::LoopedRecording log(options.log, options.loop_s);
  FastDdsDomain domain(options.domain);
  Player player(domain, options);
  std::string missing;
  if (!player.WaitForReaders(options.wait_s, &missing)) {
    std::fprintf(stderr, "fastdds_ros2_peer: no reader matched %s in ROS 2 domain %d within %g s\n", missing.c_str(),
                 options.domain, options.wait_s);
    return 1;
  }
  // The match seen here comes before the reader's side has matched this writer, and until then it drops
  // what this writer sends (the log's one CAMERA_INFO, the first frames). A Cyclone DDS reader started
  // with this peer matched it 0.5 to 1 s later (Fast DDS repeats its discovery data each second); the
  // default leaves a margin for a loaded machine.
  std::this_thread::sleep_for(std::chrono::duration<double>(options.settle_s));
  const auto start = Clock::now();
  const double start_unix_s = UnixNowS();
  int64_t first = -1;
  while (auto event = log.Next()) {
    if (first < 0) first = event->utime;
    if (options.speed > 0) {
      const auto offset = std::chrono::microseconds(static_cast<int64_t>((event->utime - first) / options.speed));
      std::this_thread::sleep_until(start + offset);
    }
    player.Send(*event);
  }
  // When the last sample left, on the host's clock (the time the stream ended, for a benchmark).
  const double end_unix_s = UnixNowS();
  std::string late;
  const bool acknowledged = player.WaitForAcknowledgments(10, &late);
  std::printf(
      "{\"published\": %s, \"seconds\": %.3f, \"passes\": %d, \"start_unix_s\": %.3f, \"first_utime\": %lld, "
      "\"end_unix_s\": %.3f, \"stamp_gaps\": %ld}\n",
      player.Json().c_str(), std::chrono::duration<double>(Clock::now() - start).count(), log.passes(), start_unix_s,
      static_cast<long long>(first), end_unix_s, log.stamp_gaps());
  std::fflush(stdout);
  if (!acknowledged) {
    std::fprintf(stderr, "fastdds_ros2_peer: samples on %s were not acknowledged within 10 s\n", late.c_str());
    return 1;
  }
  return 0;
}

}  // namespace fusecal::fastdds_peer
