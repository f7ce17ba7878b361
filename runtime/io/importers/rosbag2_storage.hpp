// One file of a rosbag2 bag, whatever its storage (MCAP or sqlite3), as Rosbag2Reader sees it: its topics
// and a cursor over its messages in log-time order. Rosbag2Reader merges the cursors of split files.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace fusecal::rosbag2_detail {

struct StoredTopic {
  std::string name;
  std::string type;
  std::string serialization_format;
  uint64_t message_count = 0;
};

struct StoredMessage {
  size_t topic = 0;  // index into StorageFile::topics()
  int64_t log_time_ns = 0;
  const uint8_t* data = nullptr;  // valid until the cursor's next Next()
  size_t size = 0;
};

class MessageCursor {
 public:
  virtual ~MessageCursor() = default;
  // The next message in log-time order (ties in the order they were stored); false at the end.
  virtual bool Next(StoredMessage& message) = 0;
};

class StorageFile {
 public:
  virtual ~StorageFile() = default;
  virtual const std::vector<StoredTopic>& topics() const = 0;
  // Messages of the topics whose flag is set (indexed like topics()).
  virtual std::unique_ptr<MessageCursor> Messages(const std::vector<bool>& selected) = 0;
  virtual std::vector<std::string> warnings() const = 0;
  virtual uint64_t bytes_read() const = 0;
};

// Both throw std::runtime_error naming the file. An MCAP file is scanned whole on opening (mcap_reader.hpp),
// which counts its messages; a sqlite3 file counts them only when asked (a query over the whole table).
std::unique_ptr<StorageFile> OpenMcapStorage(const std::string& path);
std::unique_ptr<StorageFile> OpenDb3Storage(const std::string& path, bool count_messages);

}  // namespace fusecal::rosbag2_detail
