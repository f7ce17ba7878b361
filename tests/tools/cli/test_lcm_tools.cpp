// LCM's own tools on a running pipeline: what `fusecal run` puts on udpm:// is plain LCM, so lcm-logger
// records it as messages a later `fusecal calibrate` can replay, and lcm-logplayer can be the sensors of a
// `fusecal run` that has no log of its own.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>

#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/formats/result_file.hpp"
#include "tests/support/process_utils.hpp"

namespace fusecal {
namespace {

using testing::ReadAll;
using testing::RunCommand;
using testing::StartInBackground;
const std::string kFusecal = FUSECAL_BIN;
const std::string kScenarios = SCENARIO_DIR;
// Ports of their own, so that nothing else on the machine talks into the tests.
const std::string kLoggerBus = "udpm://239.255.76.67:7697?ttl=0&recv_buf_size=67108864";
const std::string kPlayerBus = "udpm://239.255.76.67:7698?ttl=0&recv_buf_size=67108864";

std::string Temp(const std::string& name) {
  return ::testing::TempDir() + "fusecal_lcm_tools_" + std::to_string(getpid()) + "_" + name;
}

// Polls `done` every 100 ms for up to `seconds`.
template <typename Done>
bool WaitFor(double seconds, Done done) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return done();
}

int ExitCodeOf(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Events per channel of an LCM log.
std::map<std::string, int> ChannelCounts(const std::string& log) {
  std::map<std::string, int> counts;
  LogReader reader(log);
  while (auto event = reader.Next()) ++counts[event->channel];
  return counts;
}

double DifferenceDeg(const std::string& a, const std::string& b, double* translation_m) {
  const auto eval = RunCommand(kFusecal + " evaluate --result " + a + " --truth " + b);
  const auto j = nlohmann::json::parse(eval.output);
  *translation_m = j["trans_err_m"].get<double>();
  return j["rot_err_deg"].get<double>();
}

class LcmTools : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    log_ = Temp("small.lcmlog");
    const auto sim = RunCommand(kFusecal + " simulate --scenario " + kScenarios +
                                "/small-equirect.yaml --stations-only --out " + log_ + " 2>&1");
    ASSERT_EQ(sim.exit_code, 0) << sim.output;
  }
  static std::string log_;
};
std::string LcmTools::log_;

TEST_F(LcmTools, AnLcmLoggerRecordingOfARunReplaysWithCalibrateToTheRunsAnswer) {
  const std::string recording = Temp("recorded.lcmlog"), run_out = Temp("run"), replay_out = Temp("replay");
  const pid_t logger =
      StartInBackground("lcm-logger -f --lcm-url='" + kLoggerBus + "' " + recording, Temp("logger.txt"));
  ASSERT_TRUE(WaitFor(5, [&] { return access(recording.c_str(), F_OK) == 0; })) << ReadAll(Temp("logger.txt"));
  const auto run =
      RunCommand(kFusecal + " run --log " + log_ + " --speed 0 --bus '" + kLoggerBus + "' --out " + run_out + " 2>&1");
  kill(logger, SIGINT);
  ExitCodeOf(logger);
  ASSERT_EQ(run.exit_code, 0) << run.output;

  // Every message is an ordinary LCM message on its channel: the stations, the motions and the answer.
  const auto counts = ChannelCounts(recording);
  EXPECT_EQ(counts.count("FUSECAL_RELIABLE"), 0u);
  EXPECT_EQ(counts.at(channels::kStation.name), ChannelCounts(log_).at(channels::kStation.name));
  EXPECT_GT(counts.at(channels::kLidarMotion.name), 0);
  EXPECT_GT(counts.at(channels::kExtrinsic.name), 0);

  const auto replay = RunCommand(kFusecal + " calibrate --log " + recording + " --out " + replay_out + " 2>&1");
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  double translation_m = 0;
  EXPECT_LT(DifferenceDeg(replay_out + "/extrinsic.yaml", run_out + "/extrinsic.yaml", &translation_m), 1e-6);
  EXPECT_LT(translation_m, 1e-6);
}

TEST_F(LcmTools, LcmLogplayerFeedsARunWithoutALogThatCalibratesIt) {
  const std::string run_out = Temp("live"), run_text = Temp("live.txt");
  const int stations = ChannelCounts(log_).at(channels::kStation.name);
  const pid_t run = StartInBackground(kFusecal + " run --bus '" + kPlayerBus + "' --out " + run_out, run_text);
  ASSERT_TRUE(WaitFor(60, [&] { return ReadAll(run_text).find("listening to live sensors") != std::string::npos; }))
      << ReadAll(run_text);
  // The stages are up once they beat: give them a moment to subscribe before the first station.
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const auto player = RunCommand("lcm-logplayer --speed=4 --lcm-url='" + kPlayerBus + "' " + log_ + " 2>&1");
  ASSERT_EQ(player.exit_code, 0) << player.output;
  const std::string all_stations = "stations " + std::to_string(stations) + ",";
  const bool settled = WaitFor(120, [&] {
    const std::string text = ReadAll(run_text);
    const auto last = text.rfind(all_stations);
    return last != std::string::npos && text.find(" converged (", last) != std::string::npos;
  });
  kill(run, SIGINT);
  const int exit_code = ExitCodeOf(run);
  ASSERT_TRUE(settled) << ReadAll(run_text);
  EXPECT_EQ(exit_code, 0) << ReadAll(run_text);

  // Every motion calibrate uses on the same log, and the simulator's truth within calibrate's bounds.
  const auto cal = RunCommand(kFusecal + " calibrate --log " + log_ + " --out " + Temp("cal") + " 2>&1");
  ASSERT_EQ(cal.exit_code, 0) << cal.output;
  EXPECT_EQ(ReadResultFile(run_out + "/extrinsic.yaml").motions_used.size(),
            ReadResultFile(Temp("cal") + "/extrinsic.yaml").motions_used.size())
      << ReadAll(run_text);
  double translation_m = 0;
  EXPECT_LT(DifferenceDeg(run_out + "/extrinsic.yaml", log_, &translation_m), 0.1);
  EXPECT_LT(translation_m, 0.01);
}

}  // namespace
}  // namespace fusecal
