// rosbag2 bags read by Rosbag2Reader: MCAP files of our test writer (every compression, with and without
// summary, damaged in each way the reader must name), sqlite3 files, and split bag folders.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "rosbag2_test_util.hpp"
#include "tests/support/db3_test_writer.hpp"

namespace fusecal::testing {
namespace {

namespace fs = std::filesystem;

class Rosbag2 : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("fusecal_rosbag2_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  // Writes an MCAP file of the sample messages; returns its path.
  std::string Mcap(const std::string& name, const McapWriteOptions& options, size_t n = 30) {
    file_ = WriteMcap(topics_, SampleMessages(n), options);
    WriteBytes(Path(name), file_.bytes);
    return Path(name);
  }
  void Patch(const std::string& path, uint64_t offset, uint64_t value, int size) {
    std::vector<uint8_t> bytes = ReadBytes(path);
    for (int i = 0; i < size; ++i) bytes.at(offset + i) = static_cast<uint8_t>(value >> (8 * i));
    WriteBytes(path, bytes);
  }

  fs::path dir_;
  std::vector<BagTopic> topics_ = SampleTopics();
  McapTestFile file_;
};

TEST_F(Rosbag2, EveryCompressionRoundTripsBytesAndLogTimes) {
  const std::vector<GotMessage> expected = Expected(topics_, SampleMessages(30));
  for (const std::string compression : {"", "zstd", "lz4"}) {
    for (const bool summary : {true, false}) {
      SCOPED_TRACE("compression '" + compression + "', summary " + std::to_string(summary));
      Rosbag2Reader reader(Mcap("bag.mcap", {compression, true, 4, summary}));
      ASSERT_EQ(reader.topics().size(), 3u);
      for (size_t t = 0; t < 3; ++t) {
        EXPECT_EQ(reader.topics()[t].name, topics_[t].name);
        EXPECT_EQ(reader.topics()[t].type, topics_[t].type);
        EXPECT_EQ(reader.topics()[t].serialization_format, "cdr");
        EXPECT_EQ(reader.topics()[t].message_count, 10u);
      }
      EXPECT_EQ(ReadAll(reader), expected);
      EXPECT_TRUE(reader.warnings().empty());
      EXPECT_GT(reader.bytes_read(), 0u);
    }
  }
}

TEST_F(Rosbag2, MessagesOutsideChunksRoundTrip) {
  Rosbag2Reader reader(Mcap("bag.mcap", {"", false, 0, true}));
  EXPECT_EQ(ReadAll(reader), Expected(topics_, SampleMessages(30)));
  EXPECT_TRUE(reader.warnings().empty());
}

TEST_F(Rosbag2, SelectedTopicsOnlyAndEachChannelItsOwn) {
  Rosbag2Reader reader(Mcap("bag.mcap", {"lz4", true, 5, true}));
  const std::set<std::string> only = {"/imu", "/camera/image_raw"};
  EXPECT_EQ(ReadAll(reader, only), Expected(topics_, SampleMessages(30), only));
  EXPECT_EQ(ReadAll(reader, {"/lidar/points"}), Expected(topics_, SampleMessages(30), {"/lidar/points"}));
  EXPECT_TRUE(ReadAll(reader, {"/no/such/topic"}).empty());
  EXPECT_EQ(ReadAll(reader).size(), 30u);  // a second pass reads the chunks again
}

TEST_F(Rosbag2, FileCutShortMidChunkReadsTheCompleteRecordsAndWarns) {
  const std::string path = Mcap("bag.mcap", {"zstd", true, 4, true}, 12);
  const uint64_t cut = file_.chunk_offsets.at(2) + 30;
  std::vector<uint8_t> bytes = file_.bytes;
  bytes.resize(cut);
  WriteBytes(path, bytes);
  Rosbag2Reader reader(path);
  std::vector<BagMessage> complete = SampleMessages(12);
  complete.resize(8);
  EXPECT_EQ(ReadAll(reader), Expected(topics_, complete));
  ASSERT_EQ(reader.warnings().size(), 1u);
  const std::string& warning = reader.warnings()[0];
  EXPECT_NE(warning.find(path), std::string::npos) << warning;
  EXPECT_NE(warning.find("cut short"), std::string::npos) << warning;
  EXPECT_NE(warning.find("offset " + std::to_string(file_.chunk_offsets[2])), std::string::npos) << warning;
  EXPECT_NE(warning.find("dropped 30 bytes"), std::string::npos) << warning;
}

TEST_F(Rosbag2, FileCutShortInItsSummaryReadsEveryMessageAndWarns) {
  const std::string path = Mcap("bag.mcap", {"lz4", true, 4, true}, 12);
  std::vector<uint8_t> bytes = file_.bytes;
  bytes.resize(file_.data_end_offset + 13 + 20);
  WriteBytes(path, bytes);
  Rosbag2Reader reader(path);
  EXPECT_EQ(ReadAll(reader), Expected(topics_, SampleMessages(12)));
  EXPECT_EQ(reader.warnings().size(), 1u);
}

TEST_F(Rosbag2, BadCrcFailsNamingFileAndOffset) {
  const std::string path = Mcap("bag.mcap", {"zstd", true, 4, true});
  Patch(path, file_.chunk_offsets.at(1) + kChunkCrcField, 0x12345678, 4);
  ExpectErrorWith([&] { Rosbag2Reader reader(path); },
                  {path, "bad CRC", "offset " + std::to_string(file_.chunk_offsets[1])});
}

// An uncompressed chunk is not read whole when the file is opened (only its record headers): its CRC is
// checked when its messages are read, with the same error.
TEST_F(Rosbag2, BadCrcOfAnUncompressedChunkFailsWhenItsMessagesAreRead) {
  const std::string path = Mcap("bag.mcap", {"", true, 4, true});
  Patch(path, file_.chunk_offsets.at(1) + kChunkCrcField, 0x12345678, 4);
  Rosbag2Reader reader(path);
  ExpectErrorWith([&] { ReadAll(reader); }, {path, "bad CRC", "offset " + std::to_string(file_.chunk_offsets[1])});
}

TEST_F(Rosbag2, UnknownCompressionFailsNamingIt) {
  const std::string path = Mcap("bag.mcap", {"brotli", true, 4, true});
  ExpectErrorWith([&] { Rosbag2Reader reader(path); },
                  {path, "unknown compression 'brotli'", "offset " + std::to_string(file_.chunk_offsets[0])});
}

TEST_F(Rosbag2, LyingRecordLengthsFailWithoutCrash) {
  // A record claiming more than the file holds, in a file its writer closed (footer and magic at the end).
  std::string path = Mcap("bag.mcap", {"", false, 0, true});
  const uint64_t message = file_.message_offsets.at(3);
  Patch(path, message + 1, uint64_t{1} << 62, 8);
  ExpectErrorWith([&] { Rosbag2Reader reader(path); },
                  {path, "runs past the end of the file", "offset " + std::to_string(message)});
  // A chunk whose records claim more than the chunk record holds.
  path = Mcap("bag.mcap", {"lz4", true, 4, true});
  Patch(path, file_.chunk_offsets.at(0) + kChunkCompressionField + 4 + 3, uint64_t{1} << 40, 8);
  ExpectErrorWith([&] { Rosbag2Reader reader(path); },
                  {path, "truncated chunk", "offset " + std::to_string(file_.chunk_offsets[0])});
  // A record inside an uncompressed chunk (no CRC to catch it first) claiming more than the records.
  path = Mcap("bag.mcap", {"", true, 4, true, false});
  Patch(path, file_.chunk_offsets.at(1) + kChunkCompressionField + 4 + 8 + 1, 1'000'000, 8);
  ExpectErrorWith([&] { Rosbag2Reader reader(path); }, {path, "runs past the records"});
}

TEST_F(Rosbag2, LyingUncompressedSizeFailsWithoutAllocatingIt) {
  for (const uint64_t claimed : {uint64_t{1} << 31, uint64_t{1} << 50}) {
    const std::string path = Mcap("bag.mcap", {"zstd", true, 4, true});
    Patch(path, file_.chunk_offsets.at(0) + 9 + 16, claimed, 8);
    ExpectErrorWith([&] { Rosbag2Reader reader(path); }, {path, "offset " + std::to_string(file_.chunk_offsets[0])});
  }
  const std::string path = Mcap("bag.mcap", {"lz4", true, 4, true});
  Patch(path, file_.chunk_offsets.at(0) + 9 + 16, 100, 8);  // fewer than the frame holds
  ExpectErrorWith([&] { Rosbag2Reader reader(path); }, {path, "more than its uncompressed size 100"});
}

TEST_F(Rosbag2, NotAnMcapFileFailsClearly) {
  std::ofstream(Path("text.mcap")) << "hello, not a bag\n";
  ExpectErrorWith([&] { Rosbag2Reader reader(Path("text.mcap")); }, {Path("text.mcap"), "not an MCAP file"});
  std::ofstream(Path("empty.mcap")).close();
  ExpectErrorWith([&] { Rosbag2Reader reader(Path("empty.mcap")); }, {Path("empty.mcap"), "not an MCAP file"});
  ExpectErrorWith([&] { Rosbag2Reader reader(Path("missing.mcap")); }, {Path("missing.mcap")});
  ExpectErrorWith([&] { Rosbag2Reader reader(Path("text.txt")); }, {Path("text.txt"), "not a rosbag2 bag"});
}

TEST_F(Rosbag2, Db3RoundTripsBytesAndLogTimes) {
  WriteDb3(Path("bag.db3"), topics_, SampleMessages(30));
  Rosbag2Reader reader(Path("bag.db3"));
  ASSERT_EQ(reader.topics().size(), 3u);
  EXPECT_EQ(reader.topics()[1].name, "/lidar/points");
  EXPECT_EQ(reader.topics()[1].type, "sensor_msgs/msg/PointCloud2");
  EXPECT_EQ(reader.topics()[1].message_count, 10u);
  EXPECT_EQ(ReadAll(reader), Expected(topics_, SampleMessages(30)));
  EXPECT_EQ(ReadAll(reader, {"/imu"}), Expected(topics_, SampleMessages(30), {"/imu"}));
  WriteDb3(Path("no_index.db3"), topics_, SampleMessages(30), {true, true, false});
  Rosbag2Reader unindexed(Path("no_index.db3"));
  EXPECT_EQ(ReadAll(unindexed), Expected(topics_, SampleMessages(30)));
}

TEST_F(Rosbag2, Db3WithoutItsTablesFailsClearly) {
  WriteDb3(Path("no_topics.db3"), topics_, SampleMessages(3), {false, true, true});
  ExpectErrorWith([&] { Rosbag2Reader reader(Path("no_topics.db3")); }, {Path("no_topics.db3"), "topics"});
  WriteDb3(Path("no_messages.db3"), topics_, SampleMessages(3), {true, false, true});
  ExpectErrorWith([&] { Rosbag2Reader reader(Path("no_messages.db3")); }, {Path("no_messages.db3"), "messages"});
  std::ofstream(Path("text.db3")) << std::string(2000, 'x');
  ExpectErrorWith([&] { Rosbag2Reader reader(Path("text.db3")); }, {Path("text.db3"), "not a"});
}

}  // namespace
}  // namespace fusecal::testing
