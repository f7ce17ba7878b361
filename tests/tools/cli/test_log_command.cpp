// `fusecal log info|dump` on logs written by the test.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "fusecal/extrinsic_t.hpp"
#include "fusecal/station_t.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/formats/conversions.hpp"
#include "tests/support/process_utils.hpp"

namespace fusecal {
namespace {

using testing::RunCommand;

std::string WriteSampleLog() {
  const std::string path = ::testing::TempDir() + "fusecal_cli_" + std::to_string(getpid()) + ".lcmlog";
  LogWriter writer(path);
  station_t station{};
  station.utime = 5000000;
  station.id = 3;
  station.image = MatToImage(cv::Mat(10, 20, CV_8UC1, cv::Scalar(7)), "mono8", station.utime);
  PointCloud cloud;
  cloud.points.assign(100, Eigen::Vector3f(1, 2, 3));
  station.cloud = CloudToMsg(cloud, station.utime);
  station.camera = CameraToMsg(CameraParams{"equirectangular", 20, 10});
  writer.WriteMessage("STATION", station.utime, station);
  extrinsic_t extrinsic{};
  extrinsic.version = 2;
  extrinsic.status = extrinsic_t::STATUS_CONVERGED;
  extrinsic.T_camera_lidar[0] = extrinsic.T_camera_lidar[5] = extrinsic.T_camera_lidar[10] = 1;
  writer.WriteMessage("EXTRINSIC", 6000000, extrinsic);
  const char unknown[] = "0123456789abcdef";
  writer.Write("MYSTERY", 7000000, unknown, sizeof(unknown));
  writer.Close();
  return path;
}

std::vector<nlohmann::json> ParseLines(const std::string& text) {
  std::vector<nlohmann::json> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    EXPECT_NO_THROW(lines.push_back(nlohmann::json::parse(line))) << "not JSON: " << line;
  }
  return lines;
}

TEST(LogCommand, DumpPrintsOneValidJsonObjectPerEvent) {
  const std::string log = WriteSampleLog();
  const auto result = RunCommand(std::string(FUSECAL_BIN) + " log dump " + log);
  EXPECT_EQ(result.exit_code, 0);
  const auto lines = ParseLines(result.output);
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0]["channel"], "STATION");
  EXPECT_EQ(lines[0]["type"], "fusecal.station_t");
  EXPECT_EQ(lines[0]["msg"]["id"], 3);
  EXPECT_EQ(lines[0]["msg"]["cloud"]["x"]["length"], 100);  // bulk arrays by length
  EXPECT_EQ(lines[1]["msg"]["status"], "converged");
  EXPECT_EQ(lines[1]["msg"]["T_camera_lidar"].size(), 16u);
  EXPECT_TRUE(lines[2]["type"].is_null());  // unknown events are reported, not fatal
  EXPECT_TRUE(lines[2].contains("error"));
}

TEST(LogCommand, DumpFiltersChannelsAndPrintsBulkWithFull) {
  const std::string log = WriteSampleLog();
  const auto result = RunCommand(std::string(FUSECAL_BIN) + " log dump " + log + " --channel STATION --full");
  const auto lines = ParseLines(result.output);
  ASSERT_EQ(lines.size(), 1u);
  ASSERT_TRUE(lines[0]["msg"]["cloud"]["x"].is_array());
  EXPECT_EQ(lines[0]["msg"]["cloud"]["x"].size(), 100u);
}

TEST(LogCommand, InfoCountsChannels) {
  const std::string log = WriteSampleLog();
  const auto result = RunCommand(std::string(FUSECAL_BIN) + " log info " + log);
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_NE(result.output.find("STATION  count=1  type=fusecal.station_t"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("events:    3"), std::string::npos) << result.output;
}

TEST(LogCommand, GarbageAndTruncatedLogsFailClearly) {
  const std::string garbage = ::testing::TempDir() + "fusecal_garbage_" + std::to_string(getpid());
  std::ofstream(garbage) << "definitely not a log";
  for (const char* sub : {" log info ", " log dump "}) {
    const auto result = RunCommand(std::string(FUSECAL_BIN) + sub + garbage + " 2>&1");
    EXPECT_EQ(result.exit_code, 1) << result.output;
    EXPECT_NE(result.output.find("not an LCM event log"), std::string::npos) << result.output;
  }
  const std::string log = WriteSampleLog();
  EXPECT_EQ(truncate(log.c_str(), 300), 0);
  const auto result = RunCommand(std::string(FUSECAL_BIN) + " log dump " + log + " 2>&1");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("truncated"), std::string::npos) << result.output;
}

// --channel is a user's pattern, matched by RE2: a nesting 2000 deep (which overflowed std::regex's stack)
// works, one longer than the limit is refused by name, and a backtracking trap such as (S|ST)*... is
// matched in linear time.
TEST(LogCommand, ChannelPatternsThatCrashOrHangBacktrackingEnginesAreSafe) {
  const std::string log = WriteSampleLog();
  const auto dump = [&](const std::string& pattern) {
    return RunCommand(std::string(FUSECAL_BIN) + " log dump " + log + " --channel '" + pattern + "' 2>&1");
  };
  const auto nested = dump(std::string(2000, '(') + "STATION" + std::string(2000, ')'));
  EXPECT_EQ(nested.exit_code, 0) << nested.output.substr(0, 400);
  EXPECT_NE(nested.output.find("\"channel\":\"STATION\""), std::string::npos) << nested.output.substr(0, 400);
  const auto too_long = dump(std::string(5000, '(') + "STATION" + std::string(5000, ')'));
  EXPECT_EQ(too_long.exit_code, 1);
  EXPECT_NE(too_long.output.find("--channel: '((((("), std::string::npos) << too_long.output.substr(0, 400);
  EXPECT_NE(too_long.output.find("at most 4096"), std::string::npos) << too_long.output.substr(0, 400);
  const auto broken = dump("STA(TION");
  EXPECT_EQ(broken.exit_code, 1);
  EXPECT_NE(broken.output.find("not a valid regular expression: missing )"), std::string::npos) << broken.output;
  const auto trap = dump("(S|ST)*(A|AT)*ION");
  EXPECT_EQ(trap.exit_code, 0) << trap.output;
  EXPECT_NE(trap.output.find("\"channel\":\"STATION\""), std::string::npos) << trap.output;
}

}  // namespace
}  // namespace fusecal
