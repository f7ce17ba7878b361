// The iceoryx bus (iox://). Built twice: test_iox_bus starts a RouDi with pools for 8 MB messages (each
// test is its own process under ctest, so each starts its own RouDi, which ends with it);
// test_iox_bus_no_roudi (FUSECAL_IOX_TEST_NO_ROUDI) checks what happens without one.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <opencv2/core.hpp>

#include "fusecal/image_t.hpp"
#include "fusecal/status_t.hpp"
#include "runtime/bus.hpp"
#include "runtime/bus_bridge.hpp"
#include "runtime/iox/iox_chunk.hpp"
#include "runtime/iox/iox_runtime.hpp"
#include "runtime/shared_memory.hpp"
#include "stages/formats/conversions.hpp"
#include "tests/support/process_utils.hpp"
#include "tests/support/publish_order_check.hpp"
#include "tests/support/sample_messages.hpp"

namespace fusecal {
namespace {

using Clock = std::chrono::steady_clock;
using testing::MakeStatus;

// Pools for 8 MB messages; max= tells the bus what fits (as `fusecal run` does).
const shm::PoolPlan kPlan = shm::PlanPools(8u << 20, 16);
const std::string kUrl = "iox://?max=" + std::to_string(shm::LargestShmMessage(kPlan));

#ifndef FUSECAL_IOX_TEST_NO_ROUDI
// The RouDi of this test process (the echo peer process uses its parent's).
class RoudiEnvironment : public ::testing::Environment {
 public:
  void SetUp() override {
    if (std::getenv("FUSECAL_IOX_ECHO_PEER")) return;
    ASSERT_TRUE(shm::WaitUntilRoudiGone()) << "another RouDi is running on this machine; stop it to run these tests";
    roudi_ = std::make_unique<shm::RoudiProcess>(::testing::TempDir() + "fusecal_iox_roudi_" + std::to_string(getpid()),
                                                 kPlan);
    roudi_->Start();
  }
  // This process is attached to RouDi, and stopping RouDi would end it: RouDi ends when it exits.
  void TearDown() override {
    if (roudi_) roudi_->LeaveUntilExit();
  }

 private:
  std::unique_ptr<shm::RoudiProcess> roudi_;
};

template <typename Predicate>
void HandleUntil(Bus& bus, Predicate done, int max_ms = 3000) {
  const auto end = Clock::now() + std::chrono::milliseconds(max_ms);
  while (!done() && Clock::now() < end) bus.Handle(50);
}

TEST(IoxBus, TypedRoundTrip) {
  auto bus = MakeBus(kUrl);
  EXPECT_EQ(bus->url(), kUrl);
  std::vector<status_t> received;
  auto sub = bus->Subscribe<status_t>(
      "STATUS", std::function<void(const status_t&)>([&](const status_t& m) { received.push_back(m); }));
  bus->Publish("STATUS", MakeStatus("probe"));
  bus->Publish("OTHER", MakeStatus("ignored"));
  HandleUntil(*bus, [&] { return !received.empty(); });
  ASSERT_EQ(received.size(), 1u);
  EXPECT_EQ(received[0].name, "probe");
  EXPECT_EQ(received[0].counter_values[0], 4);
  EXPECT_EQ(bus->Handle(100), 0);  // OTHER has no subscriber
}

TEST(IoxBus, BetweenTwoBusesAndNotToItselfWithSelfZero) {
  auto sender = MakeBus(kUrl + "&self=0");
  auto receiver = MakeBus(kUrl);
  std::vector<std::string> names;
  int own = 0;
  auto sub = receiver->Subscribe<status_t>(
      "STATUS", std::function<void(const status_t&)>([&](const status_t& m) { names.push_back(m.name); }));
  auto echo = sender->SubscribeRaw("STATUS", [&](const RawMessage&) { ++own; });
  sender->Publish("STATUS", MakeStatus("hello"));
  HandleUntil(*receiver, [&] { return !names.empty(); });
  sender->Handle(200);
  ASSERT_EQ(names.size(), 1u);
  EXPECT_EQ(names[0], "hello");
  EXPECT_EQ(own, 0) << "self=0 delivered the bus's own message to it";
}

TEST(IoxBus, HandlerReadsTheChunkInPlace) {
  // Zero-copy: two subscriptions of one message see the same bytes at the same address, and the
  // address is not in this process's heap copy of what was sent.
  auto bus = MakeBus(kUrl);
  const std::vector<uint8_t> sent(1 << 20, 0x42);
  std::vector<const uint8_t*> seen;
  auto a = bus->SubscribeRaw("INPLACE", [&](const RawMessage& m) { seen.push_back(m.data); });
  auto b = bus->SubscribeRaw("INPLACE", [&](const RawMessage& m) { seen.push_back(m.data); });
  bus->PublishRaw("INPLACE", sent.data(), sent.size());
  HandleUntil(*bus, [&] { return seen.size() >= 2; });
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen[0], seen[1]);
  EXPECT_NE(seen[0], sent.data());
}

TEST(IoxBus, RegexSubscriptionFindsLocalAndLaterPublishers) {
  auto bus = MakeBus(kUrl);
  std::vector<std::string> channels;
  auto sub = bus->SubscribeRaw("CAM_.*", [&](const RawMessage& m) { channels.push_back(m.channel); });
  bus->PublishRaw("CAM_FRONT", "a", 1);
  bus->PublishRaw("LIDAR", "b", 1);
  HandleUntil(*bus, [&] { return !channels.empty(); });
  // A publisher on another bus, created after the subscription: found through service discovery. It
  // resends until discovered (volatile, like every late joiner).
  auto later = MakeBus(kUrl);
  const auto end = Clock::now() + std::chrono::seconds(3);
  while (std::count(channels.begin(), channels.end(), "CAM_REAR") == 0 && Clock::now() < end) {
    later->PublishRaw("CAM_REAR", "c", 1);
    bus->Handle(50);
  }
  EXPECT_EQ(std::count(channels.begin(), channels.end(), "CAM_FRONT"), 1);
  EXPECT_GE(std::count(channels.begin(), channels.end(), "CAM_REAR"), 1);
  EXPECT_EQ(std::count(channels.begin(), channels.end(), "LIDAR"), 0);
}

TEST(IoxBus, MessagesOfSeveralChannelsWaitingAtOnceArriveInPublishOrder) {
  auto bus = MakeBus(kUrl);
  testing::ExpectChannelsArriveInPublishOrder(*bus);
}

TEST(IoxBus, UnsubscribeStopsDelivery) {
  auto bus = MakeBus(kUrl);
  int count = 0;
  auto sub = bus->SubscribeRaw("A", [&](const RawMessage&) { ++count; });
  bus->PublishRaw("A", "x", 1);
  HandleUntil(*bus, [&] { return count > 0; });
  sub.Unsubscribe();
  sub.Unsubscribe();  // twice is harmless
  bus->PublishRaw("A", "x", 1);
  bus->Handle(100);
  EXPECT_EQ(count, 1);
}

TEST(IoxBus, SixMegabyteImageArrivesIntact) {
  auto bus = MakeBus(kUrl);
  cv::Mat pixels(1024, 2048, CV_8UC3);
  cv::randu(pixels, 0, 255);
  const image_t sent = MatToImage(pixels, "bgr8", 99);
  ASSERT_GT(sent.data.size(), 6000000u);
  std::vector<uint8_t> received;
  auto sub =
      bus->Subscribe<image_t>("BIG", std::function<void(const image_t&)>([&](const image_t& m) { received = m.data; }));
  bus->Publish("BIG", sent);
  HandleUntil(*bus, [&] { return !received.empty(); });
  ASSERT_EQ(received.size(), sent.data.size()) << "the 6 MB message did not arrive within 3 s";
  EXPECT_TRUE(received == sent.data);
}

TEST(IoxBus, HandlerExceptionSurfacesFromHandle) {
  auto bus = MakeBus(kUrl);
  auto sub = bus->SubscribeRaw("BOOM", [](const RawMessage&) { throw std::runtime_error("handler failed"); });
  bus->PublishRaw("BOOM", "x", 1);
  bool thrown = false;
  for (int i = 0; i < 40 && !thrown; ++i) {
    try {
      bus->Handle(50);
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "handler failed");
      thrown = true;
    }
  }
  EXPECT_TRUE(thrown) << "the exception was swallowed";
  // The bus keeps working after the error (and the chunk was handed back).
  sub.Unsubscribe();
  int count = 0;
  auto ok = bus->SubscribeRaw("FINE", [&](const RawMessage&) { ++count; });
  bus->PublishRaw("FINE", "x", 1);
  HandleUntil(*bus, [&] { return count > 0; });
  EXPECT_EQ(count, 1);
}

TEST(IoxBus, MessageLargerThanThePoolsIsRefusedWithoutAbort) {
  auto bus = MakeBus(kUrl);
  const std::vector<uint8_t> huge(shm::LargestShmMessage(kPlan) + 1, 1);
  try {
    bus->PublishRaw("HUGE", huge.data(), huge.size());
    FAIL() << "a message larger than max= was accepted";
  } catch (const BusError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(std::to_string(huge.size()) + "-byte message on HUGE"), std::string::npos) << what;
    EXPECT_NE(what.find("max=" + std::to_string(shm::LargestShmMessage(kPlan))), std::string::npos) << what;
  }
  // The process and the bus go on.
  int count = 0;
  auto sub = bus->SubscribeRaw("AFTER", [&](const RawMessage&) { ++count; });
  bus->PublishRaw("AFTER", "x", 1);
  HandleUntil(*bus, [&] { return count > 0; });
  EXPECT_EQ(count, 1);
}

// max= above what the running RouDi's pools hold (a RouDi started by hand): the bus reads the pools from
// RouDi's config and refuses the message; iceoryx itself would abort ("Could not find a fitting mempool").
TEST(IoxBus, MaxAboveTheRunningPoolsIsRefusedWithoutAbort) {
  auto bus = MakeBus("iox://?max=100000000");
  ASSERT_EQ(iox::LargestChunkPayload(), kPlan.largest_chunk());
  const std::vector<uint8_t> huge(kPlan.largest_chunk() + 1, 1);
  try {
    bus->PublishRaw("HUGE2", huge.data(), huge.size());
    FAIL() << "a message larger than every pool was accepted";
  } catch (const BusError& e) {
    EXPECT_NE(std::string(e.what()).find("larger than the largest chunk of the running RouDi's pools"),
              std::string::npos)
        << e.what();
  }
  std::vector<uint8_t> fits(kPlan.largest_chunk() - iox::kChunkHeaderBytes, 2);
  std::vector<uint8_t> received;
  auto sub = bus->SubscribeRaw("HUGE2", [&](const RawMessage& m) { received.assign(m.data, m.data + m.size); });
  bus->PublishRaw("HUGE2", fits.data(), fits.size());
  HandleUntil(*bus, [&] { return !received.empty(); });
  EXPECT_TRUE(received == fits);
}

TEST(IoxBus, RejectsBadUrlsAndChannelNames) {
  try {
    MakeBus("iox://?colour=blue");
    FAIL() << "unknown parameter accepted";
  } catch (const BusError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown parameter 'colour'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(MakeBus("iox://?depth=0"), BusError);
  EXPECT_THROW(MakeBus("iox://?depth=300"), BusError);
  EXPECT_THROW(MakeBus("iox://somehost"), BusError);
  auto bus = MakeBus(kUrl);
  const std::string long_name(101, 'A');
  try {
    bus->PublishRaw(long_name, "x", 1);
    FAIL() << "a 101-byte channel name was accepted";
  } catch (const BusError& e) {
    EXPECT_NE(std::string(e.what()).find("at most 100"), std::string::npos) << e.what();
  }
  EXPECT_THROW(bus->SubscribeRaw(long_name, [](const RawMessage&) {}), BusError);
}

TEST(IoxBus, LostMessagesShowAsSequenceGaps) {
  // A subscriber queue of 4 that is not read loses the older chunks; the bus counts them.
  auto bus = MakeBus(kUrl + "&depth=4");
  int count = 0;
  auto sub = bus->SubscribeRaw("FLOOD", [&](const RawMessage&) { ++count; });
  bus->PublishRaw("FLOOD", "x", 1);
  HandleUntil(*bus, [&] { return count > 0; });
  ASSERT_EQ(count, 1);
  for (int i = 0; i < 100; ++i) bus->PublishRaw("FLOOD", "y", 1);
  for (int i = 0; i < 5; ++i) bus->Handle(50);
  EXPECT_EQ(count, 1 + 4);
  EXPECT_EQ(bus->dropped_messages(), 96u);
}

// Across processes: this executable runs itself as an echo peer (DISABLED_EchoPeer, run only by that
// test) that sends every PING back as ECHO.
TEST(IoxBus, DISABLED_EchoPeer) {
  auto bus = MakeBus(kUrl);
  bool quit = false;
  auto ping = bus->SubscribeRaw("PING", [&](const RawMessage& m) { bus->PublishRaw("ECHO", m.data, m.size); });
  auto stop = bus->SubscribeRaw("QUIT", [&](const RawMessage&) { quit = true; });
  const auto end = Clock::now() + std::chrono::seconds(9);
  while (!quit && Clock::now() < end) bus->Handle(50);
}

extern "C" char** environ;

TEST(IoxBus, CrossProcessSmallAndSixMegabyteRoundTrip) {
  if (std::getenv("FUSECAL_IOX_ECHO_PEER")) GTEST_SKIP();
  auto bus = MakeBus(kUrl);
  std::vector<int64_t> echoed;  // utime of each echo received
  std::vector<uint8_t> last;
  auto sub = bus->Subscribe<image_t>("ECHO", std::function<void(const image_t&)>([&](const image_t& m) {
                                       echoed.push_back(m.utime);
                                       last = m.data;
                                     }));
  char self[4096] = {};
  ASSERT_GT(readlink("/proc/self/exe", self, sizeof self - 1), 0);
  std::vector<std::string> args = {self, "--gtest_filter=IoxBus.DISABLED_EchoPeer", "--gtest_also_run_disabled_tests"};
  std::vector<char*> argv = {args[0].data(), args[1].data(), args[2].data(), nullptr};
  std::vector<std::string> env_strings = {"FUSECAL_IOX_ECHO_PEER=1"};
  std::vector<char*> envp = {env_strings[0].data()};
  for (char** e = environ; *e; ++e) envp.push_back(*e);
  envp.push_back(nullptr);
  pid_t child = 0;
  posix_spawn_file_actions_t quiet;  // the peer's gtest output would interleave with ours
  posix_spawn_file_actions_init(&quiet);
  posix_spawn_file_actions_addopen(&quiet, 1, "/dev/null", O_WRONLY, 0);
  const int spawned = posix_spawn(&child, self, &quiet, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&quiet);
  ASSERT_EQ(spawned, 0);

  // Small pings until the peer is up and connected, then 6 MB images.
  image_t small = MatToImage(cv::Mat(4, 4, CV_8UC3, cv::Scalar(1, 2, 3)), "bgr8", 0);
  int64_t id = 0;
  const auto give_up = Clock::now() + std::chrono::seconds(6);
  while (echoed.empty() && Clock::now() < give_up) {
    small.utime = ++id;
    bus->Publish("PING", small);
    for (int i = 0; i < 4 && echoed.empty(); ++i) bus->Handle(50);
  }
  ASSERT_FALSE(echoed.empty()) << "no echo of a small message from the second process";
  EXPECT_TRUE(last == small.data);
  cv::Mat pixels(1024, 2048, CV_8UC3);
  cv::randu(pixels, 0, 255);
  image_t sent = MatToImage(pixels, "bgr8", 0);
  std::vector<double> times_ms;
  for (int round = 0; round < 5; ++round) {
    echoed.clear();
    sent.utime = ++id;
    const auto start = Clock::now();
    bus->Publish("PING", sent);
    HandleUntil(
        *bus, [&] { return std::find(echoed.begin(), echoed.end(), id) != echoed.end(); }, 2000);
    if (std::find(echoed.begin(), echoed.end(), id) == echoed.end()) break;
    times_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - start).count());
  }
  bus->PublishRaw("QUIT", "q", 1);
  int status = 0;
  for (int i = 0; i < 40 && waitpid(child, &status, WNOHANG) == 0; ++i) bus->Handle(50);
  if (waitpid(child, &status, WNOHANG) == 0) {
    kill(child, SIGKILL);
    waitpid(child, &status, 0);
  }
  ASSERT_EQ(times_ms.size(), 5u) << "the 6 MB ping/echo with a second process did not complete";
  EXPECT_TRUE(last == sent.data);
  std::sort(times_ms.begin(), times_ms.end());
  std::printf(
      "6 MB round trip between two processes over iox:// (encode, publish, decode, both ways): median "
      "%.1f ms, max %.1f ms\n",
      times_ms[2], times_ms[4]);
}

// What `fusecal run` puts between its coordinator (here memq://, which, like LCM multicast, hands a bus its
// own messages back) and the stages' iox:// bus: each message crosses once, both ways, and nothing echoes.
TEST(BusBridge, ForwardsBothWaysOnceWithoutEchoes) {
  auto coordinator = MakeBus("memq://");
  auto bridge_side = MakeBus(kUrl + "&self=0");
  auto stage = MakeBus(kUrl);
  BusBridge bridge(*coordinator, *bridge_side);
  int stations_at_stage = 0, status_at_coordinator = 0, status_at_stage = 0, other_at_stage = 0;
  auto s1 = stage->SubscribeRaw("STATION", [&](const RawMessage&) { ++stations_at_stage; });
  auto s2 = stage->SubscribeRaw("STATUS", [&](const RawMessage&) { ++status_at_stage; });
  auto s3 = stage->SubscribeRaw("CUSTOM_X", [&](const RawMessage&) { ++other_at_stage; });
  auto c1 = coordinator->SubscribeRaw("STATUS", [&](const RawMessage&) { ++status_at_coordinator; });
  coordinator->PublishRaw("STATION", "station", 7);
  coordinator->PublishRaw("CUSTOM_X", "x", 1);  // not a pipeline channel: the pattern forwards it
  stage->PublishRaw("STATUS", "status", 6);
  const auto end = Clock::now() + std::chrono::seconds(3);
  while (Clock::now() < end && (stations_at_stage < 1 || status_at_coordinator < 1 || other_at_stage < 1)) {
    bridge.Pump(20);
    stage->Handle(5);
    coordinator->Handle(5);
  }
  for (int i = 0; i < 20; ++i) {  // time for any echo to show
    bridge.Pump(10);
    stage->Handle(5);
    coordinator->Handle(5);
  }
  EXPECT_EQ(stations_at_stage, 1);
  EXPECT_EQ(other_at_stage, 1);
  EXPECT_EQ(status_at_coordinator, 1);
  EXPECT_EQ(status_at_stage, 1) << "the stage's own STATUS came back through the bridge";
  EXPECT_EQ(bridge.forwarded_to_stages(), 2u);
  EXPECT_EQ(bridge.forwarded_to_coordinator(), 1u);
}

#else
TEST(IoxBus, WithoutRoudiFailsFastWithAClearError) {
  ASSERT_TRUE(shm::WaitUntilRoudiGone()) << "a RouDi is running on this machine; stop it to run this test";
  const auto start = Clock::now();
  try {
    MakeBus(kUrl);
    FAIL() << "an iox:// bus started without RouDi";
  } catch (const BusError& e) {
    EXPECT_NE(std::string(e.what()).find("no iceoryx RouDi is running"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - start).count(), 1.0);
}

// `fusecal doctor --bus 'iox://'` checks the path itself: with no RouDi running it starts one for the
// check, sends 1 MB round it, and leaves no RouDi behind.
TEST(IoxDoctor, ChecksTheSharedMemoryPathOverARoudiOfItsOwn) {
  ASSERT_TRUE(shm::WaitUntilRoudiGone()) << "a RouDi is running on this machine; stop it to run this test";
  const auto doctor = testing::RunCommand(std::string(FUSECAL_BIN) + " doctor --bus 'iox://' 2>&1");
  EXPECT_NE(doctor.output.find("iceoryx RouDi: "), std::string::npos) << doctor.output;
  EXPECT_NE(doctor.output.find("coordinator bus round trip"), std::string::npos) << doctor.output;
  EXPECT_NE(doctor.output.find("iox:// round trip: a 1 MB message went round iox://?max="), std::string::npos)
      << doctor.output;
  EXPECT_NE(doctor.output.find("over a RouDi started for this check"), std::string::npos) << doctor.output;
  EXPECT_TRUE(shm::WaitUntilRoudiGone(10)) << "the doctor's RouDi outlived it";
}
#endif

TEST(IoxRuntime, ReadsTheLargestPoolFromRoudisConfig) {
  EXPECT_EQ(iox::LargestPayloadOfConfig(shm::RoudiConfigToml(kPlan)), kPlan.largest_chunk());
  EXPECT_EQ(iox::LargestPayloadOfConfig("[[segment.mempool]]\n  size = 128\ncount = 9\nsize=4096\nsizes = 1\n"), 4096u);
  EXPECT_EQ(iox::LargestPayloadOfConfig("nothing here"), 0u);
}

TEST(IoxChunk, ParsesOnlyItsOwnChunks) {
  iox::IoxChunkHeader header;
  header.magic = iox::kChunkMagic;
  header.size = 10;
  std::vector<uint8_t> chunk(iox::kChunkHeaderBytes + 10);
  std::memcpy(chunk.data(), &header, sizeof header);
  EXPECT_NE(iox::ParseChunk(chunk.data(), chunk.size()), nullptr);
  EXPECT_EQ(iox::ParseChunk(chunk.data(), chunk.size() - 1), nullptr);  // size beyond the chunk
  EXPECT_EQ(iox::ParseChunk(chunk.data(), 8), nullptr);
  header.magic = 7;
  std::memcpy(chunk.data(), &header, sizeof header);
  EXPECT_EQ(iox::ParseChunk(chunk.data(), chunk.size()), nullptr);
  iox::SequenceGaps gaps;
  EXPECT_EQ(gaps.Count(1, 5), 0u);
  EXPECT_EQ(gaps.Count(1, 6), 0u);
  EXPECT_EQ(gaps.Count(1, 9), 2u);
  EXPECT_EQ(gaps.Count(2, 1), 0u);
  EXPECT_EQ(gaps.Count(1, 3), 0u);
}

}  // namespace
}  // namespace fusecal

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
#ifndef FUSECAL_IOX_TEST_NO_ROUDI
  ::testing::AddGlobalTestEnvironment(new fusecal::RoudiEnvironment);
#endif
  return RUN_ALL_TESTS();
}
