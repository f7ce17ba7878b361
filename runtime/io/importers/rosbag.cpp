#include "runtime/io/importers/rosbag.hpp"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <utility>

#include "runtime/io/importers/bag_source.hpp"
#include "runtime/io/importers/rosbag2_reader.hpp"
#include "stages/formats/ros_sensor_conversions.hpp"
#include "stages/formats/ros_sensor_frames.hpp"

namespace fusecal {

namespace fs = std::filesystem;

namespace {

using TopicTypes = std::map<std::string, std::string>;  // topic -> message type

// ROS 1 bags are single files; a folder can only be a ROS 2 bag (whose reader says what it lacks).
std::unique_ptr<BagSource> OpenBag(const std::string& path) {
  if (Rosbag2Reader::IsRosbag2(path) || fs::is_directory(path)) return OpenRos2Bag(path);
  return OpenRos1Bag(path);
}

TopicTypes ListTopics(const BagSource& bag) {
  TopicTypes topics;
  for (const BagTopic& topic : bag.topics()) topics[topic.name] = topic.type;
  return topics;
}

std::string Listing(const TopicTypes& topics) {
  std::string text;
  for (const auto& [topic, type] : topics) text += (text.empty() ? "" : ", ") + topic + " (" + type + ")";
  return text.empty() ? "no topics" : text;
}

// The topic for `role`, checked against the kinds of message it may carry.
void RequireTopic(const BagSource& bag, const TopicTypes& topics, const std::string& topic,
                  const std::vector<RosMessageKind>& kinds, const std::string& role, const std::string& bag_path) {
  std::string accepted;
  for (const RosMessageKind kind : kinds)
    accepted += (accepted.empty() ? "" : " or ") + TypeName(kind, bag.ros_version());
  if (topic.empty())
    throw std::runtime_error("name the " + role + " topic (" + accepted + "); " + bag_path +
                             " has: " + Listing(topics));
  const auto it = topics.find(topic);
  if (it == topics.end())
    throw std::runtime_error(bag_path + " has no topic " + topic + "; it has: " + Listing(topics));
  if (std::find(kinds.begin(), kinds.end(), KindOfType(it->second)) == kinds.end())
    throw std::runtime_error(bag_path + ": topic " + topic + " is " + it->second + ", the " + role + " must be " +
                             accepted + "; the bag has: " + Listing(topics));
}

// camera_info beside the image topic or above it (/cam/image_raw/compressed -> /cam/camera_info), else
// the bag's only CameraInfo topic; empty when there is none to take.
std::string FindCameraInfoTopic(const TopicTypes& topics, const std::string& image_topic) {
  for (fs::path dir = fs::path(image_topic).parent_path(); !dir.empty(); dir = dir.parent_path()) {
    const std::string candidate = (dir / "camera_info").string();
    const auto it = topics.find(candidate);
    if (it != topics.end() && KindOfType(it->second) == RosMessageKind::kCameraInfo) return candidate;
    if (dir == dir.parent_path()) break;
  }
  std::vector<std::string> infos;
  for (const auto& [topic, type] : topics)
    if (KindOfType(type) == RosMessageKind::kCameraInfo) infos.push_back(topic);
  return infos.size() == 1 ? infos.front() : std::string();
}

CameraParams ReadCameraModel(BagSource& bag, const TopicTypes& topics, const RosbagImportOptions& options,
                             const std::string& bag_path) {
  if (options.camera) return *options.camera;
  const std::string info_type = TypeName(RosMessageKind::kCameraInfo, bag.ros_version());
  std::string topic = options.camera_info_topic;
  if (!topic.empty()) RequireTopic(bag, topics, topic, {RosMessageKind::kCameraInfo}, "camera info", bag_path);
  if (topic.empty()) topic = FindCameraInfoTopic(topics, options.image_topic);
  if (topic.empty())
    throw std::runtime_error(bag_path + " has no " + info_type + " next to " + options.image_topic +
                             ": pass --camera CAM.yaml or --camera-info-topic; the bag has: " + Listing(topics));
  std::optional<RosCameraInfo> info;
  bag.ForEach({topic}, [&](const BagMessage& m) {
    if (KindOfType(m.type()) != RosMessageKind::kCameraInfo) return true;
    info = m.CameraInfo();
    return false;
  });
  if (!info) throw std::runtime_error(bag_path + ": topic " + topic + " holds no CameraInfo message");
  return RosCameraInfoToParams(*info);
}

// Writes events in header-stamp order: bags are in arrival order, and the stamps of two sensors can
// arrive up to `window` apart out of order.
class TimeOrderedWriter {
 public:
  TimeOrderedWriter(int64_t window_us, std::function<void(int64_t first_utime)> before_first)
      : window_us_(window_us), before_first_(std::move(before_first)) {}
  void Push(int64_t utime, std::function<void()> write) {
    pending_.emplace(utime, std::move(write));
    newest_ = std::max(newest_, utime);
    while (!pending_.empty() && pending_.begin()->first < newest_ - window_us_) WriteOldest();
  }
  void Finish() {
    while (!pending_.empty()) WriteOldest();
  }

 private:
  void WriteOldest() {
    if (before_first_) std::exchange(before_first_, nullptr)(pending_.begin()->first);
    pending_.begin()->second();
    pending_.erase(pending_.begin());
  }
  int64_t window_us_, newest_ = INT64_MIN;
  std::function<void(int64_t)> before_first_;
  std::multimap<int64_t, std::function<void()>> pending_;
};

// Per topic: how many messages were skipped and the first reason, so a bad stream gives one warning.
class SkipTally {
 public:
  void Add(const std::string& topic, const std::string& reason) {
    auto& entry = skipped_[topic];
    if (entry.second++ == 0) entry.first = reason;
  }
  void Report(ImportReport& report) const {
    for (const auto& [topic, entry] : skipped_)
      report.warnings.push_back(topic + ": " + std::to_string(entry.second) +
                                " message(s) skipped, the first: " + entry.first);
  }

 private:
  std::map<std::string, std::pair<std::string, int>> skipped_;
};

// One bag message converted (RosSensorFrames, as the live ROS 2 input does) and queued for writing;
// throws on a message that cannot be used.
class MessageConverter {
 public:
  MessageConverter(const CameraParams& camera, ImportWriter& writer, TimeOrderedWriter& ordered)
      : frames_(camera), writer_(writer), ordered_(ordered) {}

  // A ROS 1 topic may carry both image types (two connections): each message says which it is.
  void Image(const BagMessage& m) {
    const RosMessageKind kind = KindOfType(m.type());
    if (kind == RosMessageKind::kImage) {
      SensorImage image = frames_.Image(m.Image(), m.arrival_utime());
      const int64_t utime = image.utime;
      ordered_.Push(utime, [this, image = std::move(image)] { writer_.WriteImage(image.utime, image.pixels); });
      return;
    }
    if (kind != RosMessageKind::kCompressedImage) throw std::runtime_error("a " + m.type() + " message, not an image");
    SensorImage image = frames_.Image(m.CompressedImage(), m.arrival_utime());
    const int64_t utime = image.utime;
    ordered_.Push(utime, [this, image = std::move(image)] {
      writer_.WriteImageFile(image.utime, image.encoded, image.encoding, image.width, image.height);
    });
  }

  void Cloud(const BagMessage& m) {
    const RosMessageKind kind = KindOfType(m.type());
    if (kind != RosMessageKind::kPointCloud2 && kind != RosMessageKind::kLivoxCustomMsg)
      throw std::runtime_error("a " + m.type() + " message, not a PointCloud2 or Livox CustomMsg");
    SensorScan scan = kind == RosMessageKind::kPointCloud2 ? frames_.Cloud(m.PointCloud2(), m.arrival_utime())
                                                           : frames_.Cloud(m.LivoxCustomMsg(), m.arrival_utime());
    const int64_t utime = scan.utime;
    ordered_.Push(utime, [this, scan = std::move(scan)] { writer_.WriteScan(scan.utime, scan.cloud); });
  }

  int unstamped() const { return frames_.unstamped(); }
  int sixteen_bit_shift() const { return frames_.sixteen_bit_shift(); }

 private:
  RosSensorFrames frames_;
  ImportWriter& writer_;
  TimeOrderedWriter& ordered_;
};

// Every image and cloud message converted and queued; an unusable one is skipped and counted.
void ConvertMessages(BagSource& bag, const RosbagImportOptions& options, MessageConverter& converter,
                     SkipTally& skipped, const ImportProgress& progress) {
  uint64_t total = 0;
  for (const BagTopic& topic : bag.topics())
    if (topic.name == options.image_topic || topic.name == options.cloud_topic) total += topic.message_count;
  int done = 0;
  bag.ForEach({options.image_topic, options.cloud_topic}, [&](const BagMessage& m) {
    try {
      if (m.topic() == options.image_topic)
        converter.Image(m);
      else
        converter.Cloud(m);
    } catch (const std::exception& e) {
      skipped.Add(m.topic(), e.what());
    }
    if (progress) progress(++done, static_cast<int>(total));
    return true;
  });
}

void AddWarnings(const BagSource& bag, const SkipTally& skipped, const MessageConverter& converter,
                 ImportReport& report) {
  skipped.Report(report);
  for (const std::string& warning : bag.warnings()) report.warnings.push_back(warning);
  if (converter.unstamped() > 0)
    report.warnings.push_back(std::to_string(converter.unstamped()) +
                              " message(s) had a zero header stamp; their bag time was used");
  if (converter.sixteen_bit_shift() > 0)
    report.warnings.push_back("16-bit images were scaled to 8 bits by 1/" +
                              std::to_string(1 << converter.sixteen_bit_shift()) + " (from the first image)");
}

}  // namespace

ImportReport ImportRosbag(const std::string& bag_path, const std::string& out_log, const RosbagImportOptions& options,
                          const ImportProgress& progress) {
  const auto bag = OpenBag(bag_path);
  const TopicTypes topics = ListTopics(*bag);
  RequireTopic(*bag, topics, options.image_topic, {RosMessageKind::kImage, RosMessageKind::kCompressedImage}, "image",
               bag_path);
  RequireTopic(*bag, topics, options.cloud_topic, {RosMessageKind::kPointCloud2, RosMessageKind::kLivoxCustomMsg},
               "cloud", bag_path);
  const CameraParams camera = ReadCameraModel(*bag, topics, options, bag_path);

  ImportWriter writer(out_log);
  TimeOrderedWriter ordered(2000000,
                            [&](int64_t first_utime) { writer.WriteCalibration(first_utime, camera, nullptr, ""); });
  MessageConverter converter(camera, writer, ordered);
  SkipTally skipped;
  ConvertMessages(*bag, options, converter, skipped, progress);
  ordered.Finish();
  ImportReport& report = writer.report();
  AddWarnings(*bag, skipped, converter, report);
  if (report.images == 0 || report.scans == 0)
    throw std::runtime_error(bag_path + ": " + std::to_string(report.images) + " images and " +
                             std::to_string(report.scans) + " scans could be read" +
                             (report.warnings.empty() ? "" : "; " + report.warnings.front()));
  writer.Commit();
  return report;
}

}  // namespace fusecal
