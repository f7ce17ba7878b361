// rosbag2 files for tests without ROS: a sqlite3 bag file (.db3) with rosbag2's tables, and the
// metadata.yaml of a bag folder. The topics and messages are those of mcap_test_writer.hpp.
#pragma once

#include <string>
#include <vector>

#include "tests/support/mcap_test_writer.hpp"

namespace fusecal::testing {

struct Db3WriteOptions {
  bool topics_table = true;
  bool messages_table = true;
  bool timestamp_index = true;  // rosbag2 creates one
};

// Writes `path` afresh (rows in the order given); throws std::runtime_error on a sqlite error.
void WriteDb3(const std::string& path, const std::vector<BagTopic>& topics, const std::vector<BagMessage>& messages,
              const Db3WriteOptions& options = Db3WriteOptions());

// metadata.yaml (version 5, as rosbag2 writes it) in `folder`, listing `files` (relative paths) and the
// topics with their message counts.
void WriteRosbag2Metadata(const std::string& folder, const std::string& storage_identifier,
                          const std::vector<std::string>& files, const std::vector<BagTopic>& topics,
                          const std::vector<BagMessage>& messages);

}  // namespace fusecal::testing
