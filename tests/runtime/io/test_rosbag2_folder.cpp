// rosbag2 bag folders: metadata.yaml and split files (MCAP or sqlite3), read as one bag in log-time order.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "rosbag2_test_util.hpp"
#include "tests/support/db3_test_writer.hpp"

namespace fusecal::testing {
namespace {

namespace fs = std::filesystem;

class Rosbag2Folder : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("fusecal_rosbag2_folder_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  // Splits the messages into files of `per_file` each, in the order given.
  std::vector<std::vector<BagMessage>> Split(const std::vector<BagMessage>& messages, size_t per_file) {
    std::vector<std::vector<BagMessage>> parts;
    for (size_t i = 0; i < messages.size(); ++i) {
      if (i % per_file == 0) parts.emplace_back();
      parts.back().push_back(messages[i]);
    }
    return parts;
  }

  fs::path dir_;
  std::vector<BagTopic> topics_ = SampleTopics();
};

TEST_F(Rosbag2Folder, SplitMcapBagReadsInLogTimeOrderWithMetadataCounts) {
  const std::vector<BagMessage> messages = SampleMessages(40);
  const auto parts = Split(messages, 15);
  std::vector<std::string> names;
  for (size_t i = 0; i < parts.size(); ++i) {
    names.push_back("bag_" + std::to_string(i) + ".mcap");
    WriteBytes(Path(names.back()), WriteMcap(topics_, parts[i], {i % 2 ? "lz4" : "zstd", true, 4, true}).bytes);
  }
  WriteRosbag2Metadata(dir_.string(), "mcap", names, topics_, messages);
  ASSERT_TRUE(Rosbag2Reader::IsRosbag2(dir_.string()));
  Rosbag2Reader reader(dir_.string());
  ASSERT_EQ(reader.topics().size(), 3u);
  EXPECT_EQ(reader.topics()[0].message_count, 14u);
  EXPECT_EQ(reader.topics()[2].type, "sensor_msgs/msg/Imu");
  EXPECT_EQ(ReadAll(reader), Expected(topics_, messages));
  EXPECT_EQ(ReadAll(reader, {"/lidar/points"}), Expected(topics_, messages, {"/lidar/points"}));
  EXPECT_TRUE(reader.warnings().empty());
}

TEST_F(Rosbag2Folder, OverlappingSplitFilesAreMerged) {
  // Odd messages in one file, even in the other: every message of one lies between two of the other.
  const std::vector<BagMessage> messages = SampleMessages(30);
  std::vector<BagMessage> odd, even;
  for (size_t i = 0; i < messages.size(); ++i) (i % 2 ? odd : even).push_back(messages[i]);
  WriteDb3(Path("bag_0.db3"), topics_, odd);
  WriteDb3(Path("bag_1.db3"), topics_, even);
  WriteRosbag2Metadata(dir_.string(), "sqlite3", {"bag_0.db3", "bag_1.db3"}, topics_, messages);
  Rosbag2Reader reader(dir_.string());
  std::vector<BagMessage> in_file_order = odd;
  in_file_order.insert(in_file_order.end(), even.begin(), even.end());  // ties: the earlier file first
  EXPECT_EQ(ReadAll(reader), Expected(topics_, in_file_order));
}

TEST_F(Rosbag2Folder, MixedStoragesAndOldStylePaths) {
  const std::vector<BagMessage> messages = SampleMessages(20);
  const auto parts = Split(messages, 10);
  WriteDb3(Path("bag_0.db3"), topics_, parts[0]);
  WriteBytes(Path("bag_1.mcap"), WriteMcap(topics_, parts[1]).bytes);
  // Early rosbag2 versions listed the files under the bag folder's own name.
  const std::string folder = dir_.filename().string();
  WriteRosbag2Metadata(dir_.string(), "sqlite3", {folder + "/bag_0.db3", folder + "/bag_1.mcap"}, topics_, messages);
  Rosbag2Reader reader(dir_.string());
  EXPECT_EQ(ReadAll(reader), Expected(topics_, messages));
}

TEST_F(Rosbag2Folder, BadFoldersFailClearly) {
  EXPECT_FALSE(Rosbag2Reader::IsRosbag2(dir_.string()));
  ExpectErrorWith([&] { Rosbag2Reader reader(dir_.string()); }, {dir_.string(), "metadata.yaml"});
  WriteRosbag2Metadata(dir_.string(), "mcap", {"bag_0.mcap"}, topics_, {});
  ExpectErrorWith([&] { Rosbag2Reader reader(dir_.string()); }, {"metadata.yaml", "bag_0.mcap"});
  std::ofstream(Path("metadata.yaml")) << "rosbag2_bagfile_information: [1, 2\n";
  ExpectErrorWith([&] { Rosbag2Reader reader(dir_.string()); }, {Path("metadata.yaml")});
  std::ofstream(Path("metadata.yaml")) << "something_else: 1\n";
  ExpectErrorWith([&] { Rosbag2Reader reader(dir_.string()); }, {Path("metadata.yaml"), "rosbag2_bagfile_information"});
  std::ofstream(Path("metadata.yaml")) << "rosbag2_bagfile_information:\n  compression_mode: FILE\n"
                                          "  relative_file_paths: [bag_0.mcap.zstd]\n";
  ExpectErrorWith([&] { Rosbag2Reader reader(dir_.string()); }, {Path("metadata.yaml"), "compression_mode FILE"});
}

}  // namespace
}  // namespace fusecal::testing
