// The shared stage main, exercised through a real process (stage_probe) on loopback multicast.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <thread>

#include "fusecal/status_t.hpp"
#include "runtime/bus.hpp"
#include "runtime/stage_main.hpp"
#include "tests/support/process_utils.hpp"

namespace fusecal {
namespace {

using testing::RunCommand;
const std::string kProbe = STAGE_PROBE_BIN;
const std::string kUrl = "udpm://239.255.76.67:7672?ttl=0&recv_buf_size=67108864";

TEST(StageMain, HelpVersionAndBadConfig) {
  auto help = RunCommand(kProbe + " --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("--config"), std::string::npos);
  EXPECT_NE(help.output.find("--bus"), std::string::npos);
  auto version = RunCommand(kProbe + " --version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.output.find("."), std::string::npos);
  const std::string config = ::testing::TempDir() + "probe_bad_" + std::to_string(getpid()) + ".yaml";
  std::ofstream(config) << "reply_prefix: x\nreply_prefx: y\n";
  auto bad = RunCommand(kProbe + " --config " + config + " 2>&1");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.output.find("reply_prefx"), std::string::npos) << bad.output;
}

TEST(StageMain, HeartbeatSurvivesHandlerErrorsAndStopsCleanlyOnSigterm) {
  auto bus = MakeBus(kUrl);
  std::vector<status_t> statuses;
  std::vector<std::string> replies;
  auto s1 = bus->Subscribe(channels::kStatus, std::function<void(const status_t&)>([&](const status_t& m) {
                             if (m.name == "probe") statuses.push_back(m);
                           }));
  auto s2 = bus->SubscribeRaw(
      "PROBE_OUT", [&](const RawMessage& m) { replies.emplace_back(reinterpret_cast<const char*>(m.data), m.size); });

  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    execl(kProbe.c_str(), kProbe.c_str(), "--bus", kUrl.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  auto pump_until = [&](const std::function<bool()>& done, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!done() && std::chrono::steady_clock::now() < end) bus->Handle(50);
    return done();
  };
  ASSERT_TRUE(pump_until([&] { return !statuses.empty(); }, 5)) << "no STATUS heartbeat from the stage";

  bus->PublishRaw("PROBE_THROW", "x", 1);
  bus->PublishRaw("PROBE_IN", "hi", 2);
  EXPECT_TRUE(pump_until([&] { return !replies.empty(); }, 3)) << "stage stopped answering after an error";
  if (!replies.empty()) {
    EXPECT_EQ(replies[0], "echo:hi");
  }

  const size_t before = statuses.size();
  pump_until([] { return false; }, 3.2);
  const size_t beats = statuses.size() - before;
  EXPECT_GE(beats, 2u);
  EXPECT_LE(beats, 5u);
  EXPECT_NE(statuses.back().last_error.find("probe asked to fail"), std::string::npos);
  EXPECT_EQ(statuses.back().pid, pid);

  kill(pid, SIGTERM);
  int status = 0;
  pid_t done = 0;
  for (int i = 0; i < 40 && done == 0; ++i) {
    done = waitpid(pid, &status, WNOHANG);
    if (done == 0) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  if (done == 0) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    FAIL() << "stage did not stop within 4 s of SIGTERM";
  }
  EXPECT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  pump_until([&] { return statuses.back().state == "stopped"; }, 1);
  EXPECT_EQ(statuses.back().state, "stopped");
}

}  // namespace
}  // namespace fusecal
