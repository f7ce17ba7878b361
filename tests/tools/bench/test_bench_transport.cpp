// The transport benchmark's CSV contract on a quick run of lcm-tuned and dds-udp: the exact
// header, one row per configuration, values from the allowed sets, delivered <= sent, and LCM with a
// tuned buffer delivering to an idle subscriber. Well under a minute.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/process_utils.hpp"

namespace {

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream stream(line);
  for (std::string field; std::getline(stream, field, ',');) fields.push_back(field);
  if (!line.empty() && line.back() == ',') fields.emplace_back();  // a trailing empty field
  return fields;
}

TEST(BenchTransport, QuickRunWritesTheCsvContract) {
  const std::string csv = ::testing::TempDir() + "bench_transport_quick.csv";
  std::remove(csv.c_str());
  const auto run = fusecal::testing::RunCommand(std::string(BENCH_TRANSPORT_BIN) +
                                                " --quick --transports lcm-tuned,dds-udp --out " + csv + " 2>&1");
  ASSERT_EQ(run.exit_code, 0) << run.output;

  std::ifstream in(csv);
  ASSERT_TRUE(in) << "no CSV at " << csv << "\n" << run.output;
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "transport,size_bytes,rate_hz,subscriber,sent,delivered,mean_ms,p99_ms,cpu_pct");

  const std::set<std::string> transports = {"lcm-tuned", "dds-udp"};  // the selected subset
  const std::set<std::string> subscribers = {"idle", "busy"};
  const std::set<std::string> rates = {"30", "0"};  // --quick: 30 Hz and flat out
  int rows = 0, lcm_tuned_idle_rows = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.empty()) continue;
    ++rows;
    const auto f = SplitFields(line);
    ASSERT_EQ(f.size(), 9u) << line;
    EXPECT_TRUE(transports.count(f[0])) << line;
    EXPECT_EQ(f[1], "2000000") << line;  // --quick: 2 MB only
    EXPECT_TRUE(rates.count(f[2])) << line;
    EXPECT_TRUE(subscribers.count(f[3])) << line;
    const int sent = std::stoi(f[4]);
    const int delivered = std::stoi(f[5]);
    EXPECT_EQ(sent, 20) << line << "\n" << run.output;
    EXPECT_GE(delivered, 0) << line;
    EXPECT_LE(delivered, sent) << line;
    if (delivered > 0) {  // latencies only when something arrived
      EXPECT_GT(std::stod(f[6]), 0.0) << line;
      EXPECT_GT(std::stod(f[7]), 0.0) << line;
    }
    if (f[0] == "lcm-tuned" && f[3] == "idle") {
      ++lcm_tuned_idle_rows;
      EXPECT_GT(delivered, 0) << line << "\n" << run.output;
    }
  }
  EXPECT_EQ(rows, 8);  // 2 transports x 1 size x 2 rates x 2 subscribers
  EXPECT_EQ(lcm_tuned_idle_rows, 2);
  // The table of docs/transport.md comes with the run.
  EXPECT_NE(run.output.find("| transport | size_bytes | rate_hz | subscriber | delivered |"), std::string::npos);
}

}  // namespace
