// MCAP files we did not write: made by the MCAP project's own TypeScript writer (@mcap/core) with real
// sensor_msgs/msg/Image and PointCloud2 CDR payloads (tests/runtime/io/mcap_reference: the script, the files
// and a JSON sidecar per file with every message as written). Our reader must give back the same topics,
// log times and bytes.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>

#include "rosbag2_test_util.hpp"

namespace fusecal::testing {
namespace {

std::vector<uint8_t> FromHex(const std::string& hex) {
  std::vector<uint8_t> bytes;
  for (size_t i = 0; i + 1 < hex.size(); i += 2)
    bytes.push_back(static_cast<uint8_t>(std::stoi(hex.substr(i, 2), nullptr, 16)));
  return bytes;
}

class McapReference : public ::testing::TestWithParam<std::string> {};

TEST_P(McapReference, TopicsLogTimesAndPayloadsAreThoseWritten) {
  const std::string base = std::string(MCAP_REFERENCE_DIR) + "/" + GetParam();
  std::ifstream sidecar_file(base + ".json");
  ASSERT_TRUE(sidecar_file) << base << ".json";
  const nlohmann::json sidecar = nlohmann::json::parse(sidecar_file);
  Rosbag2Reader reader(base + ".mcap");
  const auto& topics = sidecar.at("topics");
  ASSERT_EQ(reader.topics().size(), topics.size());
  for (size_t t = 0; t < topics.size(); ++t) {
    EXPECT_EQ(reader.topics()[t].name, topics[t].at("name").get<std::string>());
    EXPECT_EQ(reader.topics()[t].type, topics[t].at("type").get<std::string>());
    EXPECT_EQ(reader.topics()[t].serialization_format, topics[t].at("serialization_format").get<std::string>());
    EXPECT_EQ(reader.topics()[t].message_count, 10u);
  }
  std::vector<GotMessage> expected;
  for (const auto& m : sidecar.at("messages"))
    expected.push_back({m.at("topic").get<std::string>(), std::stoll(m.at("log_time_ns").get<std::string>()),
                        FromHex(m.at("data_hex").get<std::string>())});
  std::stable_sort(expected.begin(), expected.end(),
                   [](const GotMessage& a, const GotMessage& b) { return a.log_time_ns < b.log_time_ns; });
  ASSERT_EQ(expected.size(), 20u);
  EXPECT_EQ(ReadAll(reader), expected);
  EXPECT_TRUE(reader.warnings().empty());
}

INSTANTIATE_TEST_SUITE_P(TypeScriptWriter, McapReference,
                         ::testing::Values("zstd_chunked", "lz4_chunked", "uncompressed_chunked", "unchunked"));

}  // namespace
}  // namespace fusecal::testing
