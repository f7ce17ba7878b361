// An MCAP file as one file of a rosbag2 bag (rosbag2_storage.hpp): rosbag2 writes one channel per topic,
// with the ROS 2 type as the schema name and "cdr" as the message encoding; channels sharing a topic
// become one topic.
#include <map>

#include "runtime/io/importers/mcap_reader.hpp"
#include "runtime/io/importers/rosbag2_storage.hpp"

namespace fusecal::rosbag2_detail {

namespace {

class McapTopicCursor : public MessageCursor {
 public:
  McapTopicCursor(std::unique_ptr<mcap::McapCursor> cursor, const std::vector<size_t>& topic_of_channel)
      : cursor_(std::move(cursor)), topic_of_channel_(topic_of_channel) {}
  bool Next(StoredMessage& message) override {
    mcap::Message m;
    if (!cursor_->Next(m)) return false;
    message.topic = topic_of_channel_[m.channel];
    message.log_time_ns = m.log_time_ns;
    message.data = m.data;
    message.size = m.size;
    return true;
  }

 private:
  std::unique_ptr<mcap::McapCursor> cursor_;
  const std::vector<size_t>& topic_of_channel_;
};

class McapStorage : public StorageFile {
 public:
  explicit McapStorage(const std::string& path) : reader_(path) {
    std::map<std::string, size_t> by_name;
    for (const mcap::Channel& channel : reader_.channels()) {
      const auto [it, added] = by_name.emplace(channel.topic, topics_.size());
      if (added) topics_.push_back({channel.topic, channel.schema_name, channel.message_encoding, 0});
      topics_[it->second].message_count += channel.message_count;
      topic_of_channel_.push_back(it->second);
    }
  }

  const std::vector<StoredTopic>& topics() const override { return topics_; }

  std::unique_ptr<MessageCursor> Messages(const std::vector<bool>& selected) override {
    std::vector<bool> channels(topic_of_channel_.size());
    for (size_t i = 0; i < channels.size(); ++i) channels[i] = selected.at(topic_of_channel_[i]);
    return std::make_unique<McapTopicCursor>(reader_.Messages(channels), topic_of_channel_);
  }

  std::vector<std::string> warnings() const override { return reader_.warnings(); }
  uint64_t bytes_read() const override { return reader_.bytes_read(); }

 private:
  mcap::McapReader reader_;
  std::vector<StoredTopic> topics_;
  std::vector<size_t> topic_of_channel_;  // index into topics_, per channel
};

}  // namespace

std::unique_ptr<StorageFile> OpenMcapStorage(const std::string& path) { return std::make_unique<McapStorage>(path); }

}  // namespace fusecal::rosbag2_detail
