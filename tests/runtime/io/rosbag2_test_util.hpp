// What the rosbag2 reader tests share: sample topics and messages, reading a whole bag back, and the
// messages a bag should give (stable-sorted by log time).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "runtime/io/importers/rosbag2_reader.hpp"
#include "tests/support/mcap_test_writer.hpp"

namespace fusecal::testing {

struct GotMessage {
  std::string topic;
  int64_t log_time_ns = 0;
  std::vector<uint8_t> data;
  bool operator==(const GotMessage& o) const {
    return topic == o.topic && log_time_ns == o.log_time_ns && data == o.data;
  }
};

inline std::ostream& operator<<(std::ostream& out, const GotMessage& m) {
  return out << m.topic << " @" << m.log_time_ns << " (" << m.data.size() << " bytes)";
}

inline std::vector<BagTopic> SampleTopics() {
  return {{"/camera/image_raw", "sensor_msgs/msg/Image"},
          {"/lidar/points", "sensor_msgs/msg/PointCloud2"},
          {"/imu", "sensor_msgs/msg/Imu"}};
}

// n messages over the three topics, sizes from 0 to a few kB (compressible and not), log times rising
// by 10 ms with two written late and one pair sharing a stamp.
inline std::vector<BagMessage> SampleMessages(size_t n, int64_t start_ns = 1'700'000'000'000'000'000) {
  std::vector<BagMessage> messages;
  for (size_t i = 0; i < n; ++i) {
    BagMessage m;
    m.topic = i % 3;
    m.log_time_ns = start_ns + static_cast<int64_t>(i) * 10'000'000;
    m.data.resize((i * 577) % 3000);
    for (size_t k = 0; k < m.data.size(); ++k) m.data[k] = static_cast<uint8_t>(i % 2 ? k * 31 + i : k / 64);
    messages.push_back(std::move(m));
  }
  if (n > 6) {
    std::swap(messages[3].log_time_ns, messages[5].log_time_ns);  // 5 is written after 3 but is earlier
    messages[6].log_time_ns = messages[4].log_time_ns;            // a tie: file order decides
  }
  return messages;
}

inline std::vector<GotMessage> Expected(const std::vector<BagTopic>& topics, std::vector<BagMessage> messages,
                                        const std::set<std::string>& only = {}) {
  std::stable_sort(messages.begin(), messages.end(),
                   [](const BagMessage& a, const BagMessage& b) { return a.log_time_ns < b.log_time_ns; });
  std::vector<GotMessage> expected;
  for (const BagMessage& m : messages)
    if (only.empty() || only.count(topics[m.topic].name))
      expected.push_back({topics[m.topic].name, m.log_time_ns, m.data});
  return expected;
}

inline std::vector<GotMessage> ReadAll(Rosbag2Reader& reader, const std::set<std::string>& only = {}) {
  std::vector<GotMessage> got;
  reader.ForEach(only, [&](const Rosbag2Message& m) {
    got.push_back({m.topic->name, m.log_time_ns, std::vector<uint8_t>(m.data, m.data + m.size)});
  });
  return got;
}

// Runs `f` and expects a std::runtime_error whose message holds every one of `parts`.
inline void ExpectErrorWith(const std::function<void()>& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one with: " << parts.front();
  } catch (const std::runtime_error& e) {
    for (const std::string& part : parts)
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << "'" << e.what() << "' lacks '" << part << "'";
  }
}

}  // namespace fusecal::testing
