// ROS 2 bags (rosbag2) as raw messages: the container layer only (MCAP or sqlite3), no ROS library.
// The MCAP reading is ours (mcap_reader.hpp), sqlite3 goes through libsqlite3 (db3_storage.cpp), and
// rosbag2_reader.cpp reads the bag folder (metadata.yaml, split files) and merges the files' messages in
// log-time order; rosbag2_storage.hpp is what the two storages show it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace fusecal {

// ROS 2 bags (rosbag2): a folder with metadata.yaml and one or more .mcap or .db3 files (split bags, read
// in the order metadata.yaml lists them), or a single .mcap or .db3 file. Messages come out as the
// serialized bytes (CDR) with their topic; decoding is the caller's.
struct Rosbag2Topic {
  std::string name;                  // "/camera/image_raw"
  std::string type;                  // "sensor_msgs/msg/Image"
  std::string serialization_format;  // "cdr"
  uint64_t message_count = 0;        // 0 when the bag does not say
};
struct Rosbag2Message {
  const Rosbag2Topic* topic;
  int64_t log_time_ns;  // receive time of the recorder
  const uint8_t* data;
  size_t size;  // valid during the callback only
};

namespace rosbag2_detail {
class StorageFile;
}

class Rosbag2Reader {
 public:
  // Opens every file of the bag and indexes each MCAP file in one linear pass (its summary is not
  // trusted), so the errors ForEach names below may already come from here.
  explicit Rosbag2Reader(const std::string& path);  // throws std::runtime_error naming the path
  ~Rosbag2Reader();
  static bool IsRosbag2(const std::string& path);  // folder with metadata.yaml, *.mcap, *.db3
  const std::vector<Rosbag2Topic>& topics() const;
  // Calls visit for every message of the named topics (all when empty), in log-time order over the
  // whole bag (split files included). Throws std::runtime_error naming file and byte offset on a
  // truncated chunk, bad CRC, lying length, unknown compression.
  void ForEach(const std::set<std::string>& topic_names, const std::function<void(const Rosbag2Message&)>& visit);
  // What was read around (e.g. "file.mcap: no summary (recording cut short); read to the last complete
  // record at offset N, dropped M bytes"); empty when nothing.
  const std::vector<std::string>& warnings() const;
  // Bytes read from the bag's files so far (MCAP: records read from disk, chunks re-read by ForEach
  // counted again; sqlite3: message payloads), for MB/s reports.
  uint64_t bytes_read() const;

 private:
  void MergeTopics();

  std::string path_;
  std::vector<std::unique_ptr<rosbag2_detail::StorageFile>> files_;
  std::vector<Rosbag2Topic> topics_;
  // Per file: the index in topics_ of each of the file's own topics.
  std::vector<std::vector<size_t>> file_topics_;
  std::vector<std::string> warnings_;
};

}  // namespace fusecal
