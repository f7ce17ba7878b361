#include "tests/support/recorded_bags.hpp"

#include <filesystem>

#include "tests/support/db3_test_writer.hpp"

namespace fusecal::testing {

std::string Ros2TypeName(const RosAnyMessage& msg) {
  const char* const names[] = {"Image", "CompressedImage", "PointCloud2", "CameraInfo"};
  return std::string("sensor_msgs/msg/") + names[msg.index()];
}

std::vector<uint8_t> SerializeCdr(const RecordedMessage& message) {
  if (!message.cdr.empty()) return message.cdr;
  return std::visit([&](const auto& msg) { return EncodeCdr(msg, message.order); }, message.msg);
}

void ToRos2Bag(const std::vector<RecordedMessage>& recording, std::vector<testing::BagTopic>& topics,
               std::vector<testing::BagMessage>& messages) {
  for (const RecordedMessage& r : recording) {
    size_t index = 0;
    while (index < topics.size() && topics[index].name != r.topic) ++index;
    if (index == topics.size()) topics.push_back({r.topic, Ros2TypeName(r.msg), "cdr"});
    messages.push_back({index, r.arrival_utime * 1000, SerializeCdr(r)});
  }
}

void WriteMcapBag(const std::string& path, const std::vector<RecordedMessage>& recording,
                  const testing::McapWriteOptions& options) {
  std::vector<testing::BagTopic> topics;
  std::vector<testing::BagMessage> messages;
  ToRos2Bag(recording, topics, messages);
  testing::WriteBytes(path, testing::WriteMcap(topics, messages, options).bytes);
}

void WriteDb3Bag(const std::string& path, const std::vector<RecordedMessage>& recording) {
  std::vector<testing::BagTopic> topics;
  std::vector<testing::BagMessage> messages;
  ToRos2Bag(recording, topics, messages);
  std::filesystem::remove(path);
  testing::WriteDb3(path, topics, messages);
}

}  // namespace fusecal::testing
