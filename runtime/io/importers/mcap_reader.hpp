// A small MCAP reader of our own (the format: https://mcap.dev/spec): the data section is read linearly,
// without trusting the summary, and every length is checked against what holds it. Chunks may be
// uncompressed, zstd or lz4 (frame format); a non-zero chunk CRC is checked. A file cut short (no footer)
// is read up to its last complete record, with a warning saying what was dropped.
//
// Steps: mcap_source (bytes by offset, from disk or memory), mcap_scan (the linear pass: channels,
// schemas, where every message is), mcap_chunk (decompression, CRC), then McapCursor (messages in
// log-time order, each chunk decompressed again when first needed and freed after its last message).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace fusecal::mcap {

class ByteSource;
struct McapIndex;

struct Channel {
  uint16_t id = 0;
  std::string topic;
  std::string message_encoding;  // "cdr" for ROS 2
  std::string schema_name;       // the ROS 2 type, "sensor_msgs/msg/Image"; empty without a schema
  std::string schema_encoding;   // "ros2msg", "ros2idl", ...
  uint64_t message_count = 0;    // counted by the scan
};

struct Message {
  size_t channel = 0;  // index into McapReader::channels()
  int64_t log_time_ns = 0;
  const uint8_t* data = nullptr;  // valid until the cursor's next Next()
  size_t size = 0;
};

struct Limits {
  // The largest chunk accepted once uncompressed: a guard against sizes that lie, far above what writers
  // use (rosbag2 and the MCAP libraries write chunks of about 1 MB).
  uint64_t max_chunk_bytes = uint64_t{4} << 30;
};

class McapReader;

// Messages in log-time order (ties in file order). Each chunk is decompressed when its first selected
// message comes and freed after its last, so memory holds the chunks whose time ranges overlap.
class McapCursor {
 public:
  ~McapCursor();
  McapCursor(const McapCursor&) = delete;
  McapCursor& operator=(const McapCursor&) = delete;
  // Throws std::runtime_error naming the file and offset when a chunk no longer reads as it did in the scan.
  bool Next(Message& message);

 private:
  friend class McapReader;
  McapCursor(McapReader& reader, std::vector<uint32_t> order);
  void ReleasePrevious();
  const uint8_t* ChunkData(uint32_t chunk);

  McapReader& reader_;
  std::vector<uint32_t> order_;  // indices into the index's messages, sorted by log time
  size_t next_ = 0;
  std::vector<uint32_t> pending_;  // per chunk: selected messages not yet returned
  std::vector<std::vector<uint8_t>> chunk_data_;
  // The memory of the last chunk let go, read into again: a fresh multi-megabyte buffer per chunk cost
  // page faults that made an uncompressed bag slower to read than the same bytes as a ROS 1 bag.
  std::vector<uint8_t> spare_;
  std::vector<uint8_t> loose_;  // the current message when it is outside any chunk
  bool has_previous_ = false;
};

class McapReader {
 public:
  // Scans the file; throws std::runtime_error "<path>: <what> at offset <N>" on a malformed file.
  explicit McapReader(const std::string& path, const Limits& limits = Limits());
  // The same from any source (ReadMcapFromMemory); `name` stands for the file in messages.
  McapReader(const std::string& name, std::unique_ptr<ByteSource> source, const Limits& limits);
  ~McapReader();
  McapReader(const McapReader&) = delete;
  McapReader& operator=(const McapReader&) = delete;

  const std::string& name() const { return name_; }
  const std::vector<Channel>& channels() const;
  const std::vector<std::string>& warnings() const;
  uint64_t bytes_read() const;
  // Messages of the channels whose flag is set (indexed like channels(); all when empty). The reader must
  // outlive the cursor.
  std::unique_ptr<McapCursor> Messages(const std::vector<bool>& selected);

 private:
  friend class McapCursor;
  std::string name_;
  std::unique_ptr<ByteSource> source_;
  Limits limits_;
  std::unique_ptr<McapIndex> index_;
};

// An MCAP file held in memory (the bytes are copied), as the fuzz entry reads it.
std::unique_ptr<McapReader> ReadMcapFromMemory(const std::string& name, const uint8_t* data, size_t size,
                                               const Limits& limits = Limits());

}  // namespace fusecal::mcap
