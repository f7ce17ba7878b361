#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include "fusecal/status_t.hpp"
#include "runtime/bus.hpp"
#include "runtime/lcm_log.hpp"

namespace fusecal {
namespace {

std::string TempPath(const std::string& name) {
  return ::testing::TempDir() + "fusecal_" + name + "_" + std::to_string(::getpid()) + ".lcmlog";
}

void WriteThreeEvents(const std::string& path) {
  LogWriter writer(path);
  for (int i = 0; i < 3; ++i) {
    status_t s{};
    s.utime = 1000 + i;
    s.name = "n" + std::to_string(i);
    writer.WriteMessage("STATUS", s.utime, s);
  }
  writer.Close();
}

TEST(LcmLog, WriteThenReadBack) {
  const std::string path = TempPath("rw");
  WriteThreeEvents(path);
  LogReader reader(path);
  int n = 0;
  while (auto event = reader.Next()) {
    EXPECT_EQ(event->channel, "STATUS");
    EXPECT_EQ(event->utime, 1000 + n);
    EXPECT_EQ(event->event_number, n);
    ++n;
  }
  EXPECT_EQ(n, 3);
  EXPECT_TRUE(reader.problems().empty());
}

TEST(LcmLog, LcmOwnFileProviderReadsOurLogs) {
  const std::string path = TempPath("lcmfile");
  WriteThreeEvents(path);
  auto bus = MakeBus("file://" + path + "?speed=0");
  std::vector<std::string> names;
  auto sub = bus->Subscribe<status_t>(
      "STATUS", std::function<void(const status_t&)>([&](const status_t& m) { names.push_back(m.name); }));
  for (int i = 0; i < 3; ++i) bus->Handle(1000);
  EXPECT_EQ(names, (std::vector<std::string>{"n0", "n1", "n2"}));
}

TEST(LcmLog, TruncatedLogIsReported) {
  const std::string path = TempPath("trunc");
  WriteThreeEvents(path);
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), bytes.size() - 5);
  LogReader reader(path);
  int n = 0;
  while (reader.Next()) ++n;
  EXPECT_EQ(n, 2);
  ASSERT_EQ(reader.problems().size(), 1u);
  EXPECT_NE(reader.problems()[0].find("truncated"), std::string::npos);
}

TEST(LcmLog, GarbageInTheMiddleIsSkipped) {
  const std::string path = TempPath("garbage");
  WriteThreeEvents(path);
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const size_t one_event = bytes.size() / 3;
  bytes.insert(one_event, "this is not an event");
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), bytes.size());
  LogReader reader(path);
  int n = 0;
  while (reader.Next()) ++n;
  EXPECT_EQ(n, 3);
  ASSERT_EQ(reader.problems().size(), 1u);
  EXPECT_NE(reader.problems()[0].find("corrupt"), std::string::npos);
}

TEST(LcmLog, NonLogFileIsRejected) {
  const std::string path = TempPath("notalog");
  std::ofstream(path) << "hello, I am a text file and not an LCM log\n";
  EXPECT_THROW(LogReader{path}, LogError);
  EXPECT_THROW(LogReader{"/nonexistent/file.lcmlog"}, LogError);
}

}  // namespace
}  // namespace fusecal
