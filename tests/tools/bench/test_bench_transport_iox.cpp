// The zero-copy rows of the transport benchmark on a quick run: `iox` and `iceoryx-raw` run on a
// RouDi the benchmark starts, and at 30 Hz both deliver all 20 messages to the idle and to the busy
// subscriber, and both really ran on shared memory. Under half a minute.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "runtime/shared_memory.hpp"
#include "tests/support/process_utils.hpp"

namespace {

TEST(BenchTransportIox, QuickRunOfTheZeroCopyRowsDeliversEverythingAt30Hz) {
  ASSERT_TRUE(fusecal::shm::WaitUntilRoudiGone()) << "a RouDi is running on this machine; stop it to run this test";
  const std::string csv = ::testing::TempDir() + "bench_transport_iox_quick.csv";
  std::remove(csv.c_str());
  const auto run = fusecal::testing::RunCommand(std::string(BENCH_TRANSPORT_BIN) +
                                                " --quick --transports iox,iceoryx-raw --out " + csv + " 2>&1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream in(csv);
  ASSERT_TRUE(in) << "no CSV at " << csv << "\n" << run.output;
  std::string line;
  std::getline(in, line);  // header
  int rows = 0, paced = 0;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    ++rows;
    std::vector<std::string> f;
    std::stringstream stream(line);
    for (std::string field; std::getline(stream, field, ',');) f.push_back(field);
    ASSERT_GE(f.size(), 6u) << line;
    EXPECT_TRUE(f[0] == "iox" || f[0] == "iceoryx-raw") << line;
    if (f[2] == "30") {
      ++paced;
      EXPECT_EQ(f[5], "20") << line << "\n" << run.output;
    }
  }
  EXPECT_EQ(rows, 8);  // 2 transports x 1 size x 2 rates x 2 subscribers
  EXPECT_EQ(paced, 4);
  EXPECT_EQ(run.output.find("did not use shared memory"), std::string::npos) << run.output;
  EXPECT_TRUE(fusecal::shm::WaitUntilRoudiGone()) << "the benchmark's RouDi outlived it";
}

}  // namespace
