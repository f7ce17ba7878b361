#include "importers/rosbag.hpp"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <utility>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "importers/ros_messages.hpp"

namespace fusecal {

namespace fs = std::filesystem;

namespace {

const char* const kImage = "sensor_msgs/Image";
const char* const kCompressedImage = "sensor_msgs/CompressedImage";
const char* const kCloud = "sensor_msgs/PointCloud2";
const char* const kCameraInfo = "sensor_msgs/CameraInfo";

using TopicTypes = std::map<std::string, std::string>;  // topic -> message type

std::unique_ptr<rosbag::Bag> OpenBag(const std::string& path) {
  const std::string ext = fs::path(path).extension().string();
  if (ext == ".db3" || ext == ".mcap" || (fs::is_directory(path) && fs::exists(fs::path(path) / "metadata.yaml")))
    throw std::runtime_error(path + " is a ROS 2 bag; fusecal reads ROS 1 bags (.bag). Convert it first, e.g. "
                             "`rosbags-convert --src " + path + " --dst out.bag` (Python package rosbags)");
  if (!fs::is_regular_file(path)) throw std::runtime_error(path + ": no such file");
  auto bag = std::make_unique<rosbag::Bag>();
  try {
    bag->open(path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error(path + ": not a readable ROS 1 bag (" + e.what() + ")");
  }
  return bag;
}

TopicTypes ListTopics(const rosbag::Bag& bag) {
  TopicTypes topics;
  rosbag::View view(bag);
  for (const rosbag::ConnectionInfo* connection : view.getConnections())
    topics[connection->topic] = connection->datatype;
  return topics;
}

std::string Listing(const TopicTypes& topics) {
  std::string text;
  for (const auto& [topic, type] : topics) text += (text.empty() ? "" : ", ") + topic + " (" + type + ")";
  return text.empty() ? "no topics" : text;
}

// The topic for `role`, checked against the types it may have.
void RequireTopic(const TopicTypes& topics, const std::string& topic, const std::vector<std::string>& types,
                  const std::string& role, const std::string& bag_path) {
  std::string accepted;
  for (const auto& type : types) accepted += (accepted.empty() ? "" : " or ") + type;
  if (topic.empty())
    throw std::runtime_error("name the " + role + " topic (" + accepted + "); " + bag_path + " has: " +
                             Listing(topics));
  const auto it = topics.find(topic);
  if (it == topics.end())
    throw std::runtime_error(bag_path + " has no topic " + topic + "; it has: " + Listing(topics));
  if (std::find(types.begin(), types.end(), it->second) == types.end())
    throw std::runtime_error(bag_path + ": topic " + topic + " is " + it->second + ", the " + role + " must be " +
                             accepted + "; the bag has: " + Listing(topics));
}

// camera_info beside the image topic or above it (/cam/image_raw/compressed -> /cam/camera_info), else
// the bag's only CameraInfo topic; empty when there is none to take.
std::string FindCameraInfoTopic(const TopicTypes& topics, const std::string& image_topic) {
  for (fs::path dir = fs::path(image_topic).parent_path(); !dir.empty(); dir = dir.parent_path()) {
    const std::string candidate = (dir / "camera_info").string();
    const auto it = topics.find(candidate);
    if (it != topics.end() && it->second == kCameraInfo) return candidate;
    if (dir == dir.parent_path()) break;
  }
  std::vector<std::string> infos;
  for (const auto& [topic, type] : topics)
    if (type == kCameraInfo) infos.push_back(topic);
  return infos.size() == 1 ? infos.front() : std::string();
}

CameraParams ReadCameraModel(const rosbag::Bag& bag, const TopicTypes& topics, const RosbagImportOptions& options,
                             const std::string& bag_path) {
  if (options.camera) return *options.camera;
  std::string topic = options.camera_info_topic;
  if (!topic.empty()) RequireTopic(topics, topic, {kCameraInfo}, "camera info", bag_path);
  if (topic.empty()) topic = FindCameraInfoTopic(topics, options.image_topic);
  if (topic.empty())
    throw std::runtime_error(bag_path + " has no sensor_msgs/CameraInfo next to " + options.image_topic +
                             ": pass --camera CAM.yaml or --camera-info-topic; the bag has: " + Listing(topics));
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::MessageInstance& m : view) {
    const auto info = m.instantiate<sensor_msgs::CameraInfo>();
    if (info) return RosCameraInfoToParams(*info);
  }
  throw std::runtime_error(bag_path + ": topic " + topic + " holds no CameraInfo message");
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
      report.warnings.push_back(topic + ": " + std::to_string(entry.second) + " message(s) skipped, the first: " +
                                entry.first);
  }

 private:
  std::map<std::string, std::pair<std::string, int>> skipped_;
};

// One bag message converted and queued for writing; throws on a message that cannot be used.
class MessageConverter {
 public:
  MessageConverter(const CameraParams& camera, ImportWriter& writer, TimeOrderedWriter& ordered)
      : camera_(camera), writer_(writer), ordered_(ordered) {}

  // A topic may carry both types (two connections); instantiate<> does not check which one it reads.
  void Image(const rosbag::MessageInstance& m) {
    if (m.getDataType() == kImage) {
      const auto raw = m.instantiate<sensor_msgs::Image>();
      if (!raw) throw std::runtime_error("an Image message that does not decode");
      const cv::Mat image = RosImageToMat(*raw, scaler_);
      CheckSize(image);
      const int64_t utime = Stamp(raw->header.stamp, m);
      ordered_.Push(utime, [this, image, utime] {
        writer_.WriteImage(utime, image);
      });
      return;
    }
    if (m.getDataType() != kCompressedImage) throw std::runtime_error("a " + m.getDataType() + " message, not an image");
    const auto compressed = m.instantiate<sensor_msgs::CompressedImage>();
    if (!compressed) throw std::runtime_error("a CompressedImage message that does not decode");
    cv::Mat decoded;
    const std::string encoding = RosCompressedFormat(*compressed, &decoded);
    CheckSize(decoded);
    const int64_t utime = Stamp(compressed->header.stamp, m);
    ordered_.Push(utime, [this, compressed, encoding, utime, w = decoded.cols, h = decoded.rows] {
      writer_.WriteImageFile(utime, compressed->data, encoding, w, h);
    });
  }

  void Cloud(const rosbag::MessageInstance& m) {
    if (m.getDataType() != kCloud) throw std::runtime_error("a " + m.getDataType() + " message, not a PointCloud2");
    const auto msg = m.instantiate<sensor_msgs::PointCloud2>();
    if (!msg) throw std::runtime_error("a PointCloud2 message that does not decode");
    int dropped = 0;
    PointCloud cloud = RosCloudToPointCloud(*msg, &dropped);
    if (cloud.empty()) throw std::runtime_error("no finite point in " + std::to_string(dropped));
    const int64_t utime = Stamp(msg->header.stamp, m);
    ordered_.Push(utime, [this, cloud = std::move(cloud), utime] { writer_.WriteScan(utime, cloud); });
  }

  int unstamped() const { return unstamped_; }
  int sixteen_bit_shift() const { return scaler_.shift(); }

 private:
  void CheckSize(const cv::Mat& image) const {
    if (image.cols != camera_.width || image.rows != camera_.height)
      throw std::runtime_error("image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                               ", the camera model is " + std::to_string(camera_.width) + "x" +
                               std::to_string(camera_.height));
  }
  // The header stamp (when the sensor measured), else the bag's arrival time.
  int64_t Stamp(const ros::Time& stamp, const rosbag::MessageInstance& m) {
    if (!stamp.isZero()) return RosStampToUtime(stamp);
    ++unstamped_;
    return RosStampToUtime(m.getTime());
  }

  const CameraParams& camera_;
  ImportWriter& writer_;
  TimeOrderedWriter& ordered_;
  SixteenBitScaler scaler_;
  int unstamped_ = 0;
};

}  // namespace

ImportReport ImportRosbag(const std::string& bag_path, const std::string& out_log,
                          const RosbagImportOptions& options, const ImportProgress& progress) {
  const auto bag = OpenBag(bag_path);
  const TopicTypes topics = ListTopics(*bag);
  RequireTopic(topics, options.image_topic, {kImage, kCompressedImage}, "image", bag_path);
  RequireTopic(topics, options.cloud_topic, {kCloud}, "cloud", bag_path);
  const CameraParams camera = ReadCameraModel(*bag, topics, options, bag_path);

  ImportWriter writer(out_log);
  TimeOrderedWriter ordered(2000000, [&](int64_t first_utime) {
    writer.WriteCalibration(first_utime, camera, nullptr, "");
  });
  MessageConverter converter(camera, writer, ordered);
  SkipTally skipped;
  rosbag::View view(*bag, rosbag::TopicQuery(std::vector<std::string>{options.image_topic, options.cloud_topic}));
  const int total = static_cast<int>(view.size());
  int done = 0;
  for (const rosbag::MessageInstance& m : view) {
    try {
      if (m.getTopic() == options.image_topic) converter.Image(m);
      else converter.Cloud(m);
    } catch (const std::exception& e) {
      skipped.Add(m.getTopic(), e.what());
    }
    if (progress) progress(++done, total);
  }
  ordered.Finish();
  ImportReport& report = writer.report();
  skipped.Report(report);
  if (converter.unstamped() > 0)
    report.warnings.push_back(std::to_string(converter.unstamped()) +
                              " message(s) had a zero header stamp; their bag time was used");
  if (converter.sixteen_bit_shift() > 0)
    report.warnings.push_back("16-bit images were scaled to 8 bits by 1/" +
                              std::to_string(1 << converter.sixteen_bit_shift()) + " (from the first image)");
  if (report.images == 0 || report.scans == 0)
    throw std::runtime_error(bag_path + ": " + std::to_string(report.images) + " images and " +
                             std::to_string(report.scans) + " scans could be read" +
                             (report.warnings.empty() ? "" : "; " + report.warnings.front()));
  writer.Commit();
  return report;
}

}  // namespace fusecal
