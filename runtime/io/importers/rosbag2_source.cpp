// ROS 2 bags (MCAP or sqlite3) through Rosbag2Reader, their messages decoded from CDR.
#include <exception>
#include <stdexcept>

#include "runtime/io/importers/bag_source.hpp"
#include "runtime/io/importers/rosbag2_reader.hpp"
#include "stages/formats/ros_cdr.hpp"

namespace fusecal {

namespace {

class Ros2Message : public BagMessage {
 public:
  explicit Ros2Message(const Rosbag2Message& m) : m_(m) {}
  const std::string& topic() const override { return m_.topic->name; }
  const std::string& type() const override { return m_.topic->type; }
  int64_t arrival_utime() const override { return m_.log_time_ns / 1000; }
  RosImage Image() const override { return DecodeCdrImage(Data(), m_.size); }
  RosCompressedImage CompressedImage() const override { return DecodeCdrCompressedImage(Data(), m_.size); }
  RosPointCloud2 PointCloud2() const override { return DecodeCdrPointCloud2(Data(), m_.size); }
  RosCameraInfo CameraInfo() const override { return DecodeCdrCameraInfo(Data(), m_.size); }
  RosLivoxCustomMsg LivoxCustomMsg() const override { return DecodeCdrLivoxCustomMsg(Data(), m_.size); }

 private:
  const uint8_t* Data() const {
    if (m_.topic->serialization_format != "cdr")
      throw std::runtime_error("a message serialized as '" + m_.topic->serialization_format + "', not CDR");
    return m_.data;
  }
  const Rosbag2Message& m_;
};

// Thrown through Rosbag2Reader::ForEach to end the visit early; no std::exception, so that nothing on
// the way takes it for an error.
struct StopVisit {};

class Ros2Bag : public BagSource {
 public:
  explicit Ros2Bag(const std::string& path) : reader_(path) {
    for (const Rosbag2Topic& topic : reader_.topics())
      topics_.push_back(BagTopic{topic.name, topic.type, topic.message_count});
  }

  const std::vector<BagTopic>& topics() const override { return topics_; }
  int ros_version() const override { return 2; }
  std::vector<std::string> warnings() const override { return reader_.warnings(); }

  void ForEach(const std::set<std::string>& topic_names, const std::function<bool(const BagMessage&)>& visit) override {
    // The visitor's own exceptions are carried past the reader, which would otherwise report them as
    // its own (and with a file offset).
    std::exception_ptr failure;
    try {
      reader_.ForEach(topic_names, [&](const Rosbag2Message& m) {
        bool more = false;
        try {
          more = visit(Ros2Message(m));
        } catch (...) {
          failure = std::current_exception();
        }
        if (!more) throw StopVisit{};
      });
    } catch (const StopVisit&) {
    }
    if (failure) std::rethrow_exception(failure);
  }

 private:
  Rosbag2Reader reader_;
  std::vector<BagTopic> topics_;
};

}  // namespace

std::unique_ptr<BagSource> OpenRos2Bag(const std::string& path) { return std::make_unique<Ros2Bag>(path); }

}  // namespace fusecal
