// One recording of ROS sensor messages, written as a ROS 2 bag (MCAP or sqlite3, messages in CDR) and as
// a ROS 1 bag (ros1_bag_writer.hpp), so that tests and benchmarks can import the same messages from each.
#pragma once

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "stages/formats/ros_sensor_messages.hpp"
#include "tests/support/cdr_writer.hpp"
#include "tests/support/mcap_test_writer.hpp"

namespace fusecal::testing {

using RosAnyMessage = std::variant<RosImage, RosCompressedImage, RosPointCloud2, RosCameraInfo>;

// One message of a recording, with when the recorder received it. `cdr`, when set, replaces the
// message's own serialization in ROS 2 bags (a damaged message).
struct RecordedMessage {
  std::string topic;
  int64_t arrival_utime = 0;
  RosAnyMessage msg;
  std::vector<uint8_t> cdr;
  CdrByteOrder order = CdrByteOrder::kLittle;
};

// "sensor_msgs/msg/Image" and so on.
std::string Ros2TypeName(const RosAnyMessage& msg);
std::vector<uint8_t> SerializeCdr(const RecordedMessage& message);

// The topics (in order of first appearance) and CDR messages of a ROS 2 bag.
void ToRos2Bag(const std::vector<RecordedMessage>& recording, std::vector<testing::BagTopic>& topics,
               std::vector<testing::BagMessage>& messages);

void WriteMcapBag(const std::string& path, const std::vector<RecordedMessage>& recording,
                  const testing::McapWriteOptions& options = testing::McapWriteOptions());
// Replaces any file at `path`.
void WriteDb3Bag(const std::string& path, const std::vector<RecordedMessage>& recording);

}  // namespace fusecal::testing
