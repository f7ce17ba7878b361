// ROS 1 bags through Debian's rosbag_storage: the one BagSource that sees ROS 1 headers.
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <filesystem>
#include <map>
#include <stdexcept>

#include "runtime/io/importers/bag_source.hpp"
#include "runtime/io/importers/ros_messages.hpp"
#include "stages/formats/ros1_serialized.hpp"
#include "stages/formats/ros_sensor_conversions.hpp"

namespace fusecal {

namespace {

class Ros1Message : public BagMessage {
 public:
  explicit Ros1Message(const rosbag::MessageInstance& m) : m_(m) {}
  const std::string& topic() const override { return m_.getTopic(); }
  const std::string& type() const override { return m_.getDataType(); }
  int64_t arrival_utime() const override { return RosStampToUtime(FromRos1(m_.getTime())); }
  RosImage Image() const override { return FromRos1(std::move(*Instantiate<sensor_msgs::Image>("Image"))); }
  RosCompressedImage CompressedImage() const override {
    return FromRos1(std::move(*Instantiate<sensor_msgs::CompressedImage>("CompressedImage")));
  }
  RosPointCloud2 PointCloud2() const override {
    return FromRos1(std::move(*Instantiate<sensor_msgs::PointCloud2>("PointCloud2")));
  }
  RosCameraInfo CameraInfo() const override {
    return FromRos1(std::move(*Instantiate<sensor_msgs::CameraInfo>("CameraInfo")));
  }
  // No C++ type of Livox's: the serialized bytes, decoded by name.
  RosLivoxCustomMsg LivoxCustomMsg() const override {
    std::vector<uint8_t> bytes(m_.size());
    ros::serialization::OStream stream(bytes.data(), static_cast<uint32_t>(bytes.size()));
    m_.write(stream);
    return DecodeRos1LivoxCustomMsg(bytes.data(), bytes.size());
  }

 private:
  template <typename T>
  boost::shared_ptr<T> Instantiate(const char* name) const {
    const auto msg = m_.instantiate<T>();
    if (!msg) throw std::runtime_error(std::string("a ") + name + " message that does not decode");
    return msg;
  }
  const rosbag::MessageInstance& m_;
};

class Ros1Bag : public BagSource {
 public:
  explicit Ros1Bag(const std::string& path) {
    if (!std::filesystem::is_regular_file(path)) throw std::runtime_error(path + ": no such file");
    try {
      bag_.open(path, rosbag::bagmode::Read);
    } catch (const rosbag::BagException& e) {
      throw std::runtime_error(path + ": not a readable ROS 1 bag (" + e.what() + ")");
    }
    // A topic written with two types (two connections) is listed with the last; each message still
    // carries its own type.
    std::map<std::string, std::string> types;
    rosbag::View view(bag_);
    for (const rosbag::ConnectionInfo* connection : view.getConnections())
      types[connection->topic] = connection->datatype;
    for (const auto& [name, type] : types)
      topics_.push_back(BagTopic{name, type, rosbag::View(bag_, rosbag::TopicQuery(name)).size()});
  }

  const std::vector<BagTopic>& topics() const override { return topics_; }
  int ros_version() const override { return 1; }
  std::vector<std::string> warnings() const override { return {}; }

  void ForEach(const std::set<std::string>& topic_names, const std::function<bool(const BagMessage&)>& visit) override {
    rosbag::View view(bag_, rosbag::TopicQuery(std::vector<std::string>(topic_names.begin(), topic_names.end())));
    for (const rosbag::MessageInstance& m : view)
      if (!visit(Ros1Message(m))) return;
  }

 private:
  rosbag::Bag bag_;
  std::vector<BagTopic> topics_;
};

}  // namespace

std::unique_ptr<BagSource> OpenRos1Bag(const std::string& path) { return std::make_unique<Ros1Bag>(path); }

}  // namespace fusecal
