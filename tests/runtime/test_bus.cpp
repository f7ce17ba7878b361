#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <fstream>

#include "fusecal/image_t.hpp"
#include "fusecal/status_t.hpp"
#include "runtime/bus.hpp"
#include "runtime/channel_pattern.hpp"
#include "stages/formats/conversions.hpp"
#include "tests/support/sample_messages.hpp"

namespace fusecal {
namespace {

using testing::MakeStatus;

TEST(MemqBus, TypedRoundTrip) {
  auto bus = MakeBus("memq://");
  std::vector<status_t> received;
  auto sub = bus->Subscribe<status_t>(
      "STATUS", std::function<void(const status_t&)>([&](const status_t& m) { received.push_back(m); }));
  bus->Publish("STATUS", MakeStatus("probe"));
  bus->Publish("OTHER", MakeStatus("ignored"));
  EXPECT_EQ(bus->Handle(100), 1);  // OTHER has no subscriber
  ASSERT_EQ(received.size(), 1u);
  EXPECT_EQ(received[0].name, "probe");
  EXPECT_EQ(received[0].counter_values[0], 4);
}

// The typed channels of runtime/channels.hpp with plain lambdas: the message type comes from the channel,
// and a handler may also take the raw message.
TEST(MemqBus, TypedChannelsTakePlainLambdas) {
  auto bus = MakeBus("memq://");
  std::vector<std::string> names;
  std::string raw_channel;
  auto sub = bus->Subscribe(channels::kStatus, [&](const status_t& m) { names.push_back(m.name); });
  auto with_raw = bus->Subscribe(
      channels::kStatus, [&](const status_t& m, const RawMessage& raw) { raw_channel = raw.channel + "/" + m.name; });
  bus->Publish(channels::kStatus, MakeStatus("probe"));
  EXPECT_EQ(bus->Handle(100), 2);
  EXPECT_EQ(names, std::vector<std::string>{"probe"});
  EXPECT_EQ(raw_channel, "STATUS/probe");
}

// Every bus reads how to carry a channel from the one table: raw frames are bulk, the rest state, and a
// channel the pipeline does not know is state.
TEST(Channels, TheTableSaysWhichChannelsAreBulkAndWhichAreLarge) {
  EXPECT_EQ(TraitsOfChannel("CAMERA_IMAGE").kind, ChannelKind::kBulk);
  EXPECT_EQ(TraitsOfChannel("LIDAR_SCAN").kind, ChannelKind::kBulk);
  for (const char* state : {"STATION", "LIDAR_MOTION", "CAMERA_MOTION", "FUSED_MOTIONS", "EXTRINSIC", "CAMERA_INFO"})
    EXPECT_EQ(TraitsOfChannel(state).kind, ChannelKind::kState) << state;
  EXPECT_TRUE(TraitsOfChannel("STATION").large);
  EXPECT_FALSE(TraitsOfChannel("EXTRINSIC").large);
  EXPECT_EQ(TraitsOfChannel("MY_OWN").kind, ChannelKind::kState);
  EXPECT_FALSE(IsPipelineChannel("MY_OWN"));
  // A camera's own channels are carried as the pipeline's.
  EXPECT_EQ(TraitsOfChannel("CAMERA_IMAGE_front").kind, ChannelKind::kBulk);
  EXPECT_TRUE(TraitsOfChannel("STATION_left").large);
  EXPECT_EQ(TraitsOfChannel("EXTRINSIC_left").kind, ChannelKind::kState);
  EXPECT_TRUE(IsPipelineChannel("FUSED_MOTIONS_rear"));
  EXPECT_FALSE(IsPipelineChannel("LIDAR_SCAN_front"));  // the rig's: no camera's own
  EXPECT_FALSE(IsPipelineChannel("STATION_"));
  EXPECT_STREQ(ForCamera(channels::kStation, "front").name, "STATION_front");
  EXPECT_STREQ(ForCamera(channels::kStation, "").name, "STATION");
  EXPECT_EQ(std::size(kPipelineChannels), 10u);
}

// Subscription patterns are RE2's (runtime/channel_pattern.hpp): a backtracking trap against a long
// channel name is matched in linear time, a nesting 2000 deep works, and a pattern over the length limit
// or one that does not compile is a BusError naming it, not a crash.
TEST(MemqBus, PatternsAreMatchedInLinearTimeAndBadOnesAreNamed) {
  auto bus = MakeBus("memq://");
  int trapped = 0, nested = 0;
  auto trap = bus->SubscribeRaw("(a|aa)*c", [&](const RawMessage&) { ++trapped; });
  auto deep =
      bus->SubscribeRaw(std::string(2000, '(') + "A" + std::string(2000, ')'), [&](const RawMessage&) { ++nested; });
  bus->PublishRaw(std::string(20000, 'a'), "x", 1);
  bus->PublishRaw("aac", "x", 1);
  bus->PublishRaw("A", "x", 1);
  bus->Handle(100);
  EXPECT_EQ(trapped, 1);
  EXPECT_EQ(nested, 1);
  try {
    bus->SubscribeRaw(std::string(ChannelPattern::kMaxPatternBytes + 1, '.'), [](const RawMessage&) {});
    ADD_FAILURE() << "a pattern over the length limit was accepted";
  } catch (const BusError& e) {
    EXPECT_NE(std::string(e.what()).find("LCM subscribe: '....."), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("at most 4096"), std::string::npos) << e.what();
  }
  EXPECT_THROW(bus->SubscribeRaw("A(B", [](const RawMessage&) {}), BusError);
}

TEST(MemqBus, UnsubscribeStopsDelivery) {
  auto bus = MakeBus("memq://");
  int count = 0;
  auto sub = bus->SubscribeRaw("A", [&](const RawMessage&) { ++count; });
  bus->PublishRaw("A", "x", 1);
  bus->Handle(100);
  sub.Unsubscribe();
  sub.Unsubscribe();  // twice is harmless
  bus->PublishRaw("A", "x", 1);
  bus->Handle(50);
  EXPECT_EQ(count, 1);
}

TEST(MemqBus, HandlerExceptionSurfacesFromHandle) {
  auto bus = MakeBus("memq://");
  auto sub = bus->SubscribeRaw("BOOM", [](const RawMessage&) { throw std::runtime_error("handler failed"); });
  bus->PublishRaw("BOOM", "x", 1);
  try {
    bus->Handle(100);
    FAIL() << "the exception was swallowed";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "handler failed");
  }
  // The bus keeps working after the error.
  int count = 0;
  auto sub2 = bus->SubscribeRaw("OK", [&](const RawMessage&) { ++count; });
  bus->PublishRaw("OK", "y", 1);
  bus->Handle(100);
  EXPECT_EQ(count, 1);
}

// In one process (calibrate), a stage that cannot use a message must not keep it from the others.
TEST(MemqBus, AFailingHandlerDoesNotKeepTheMessageFromTheOthers) {
  auto bus = MakeBus("memq://");
  int before = 0, after = 0;
  auto first = bus->SubscribeRaw("STATION", [&](const RawMessage&) { ++before; });
  auto failing = bus->SubscribeRaw("STATION", [](const RawMessage&) { throw std::runtime_error("bad scan"); });
  auto last = bus->SubscribeRaw("STATION", [&](const RawMessage&) { ++after; });
  bus->PublishRaw("STATION", "x", 1);
  EXPECT_THROW(bus->Handle(100), std::runtime_error);
  EXPECT_EQ(before, 1);
  EXPECT_EQ(after, 1) << "the message must reach every handler despite the error";
}

TEST(MemqBus, WrongTypeOnChannelIsAClearError) {
  auto bus = MakeBus("memq://");
  auto sub = bus->Subscribe<image_t>("STATUS", std::function<void(const image_t&)>([](const image_t&) {}));
  bus->Publish("STATUS", MakeStatus("x"));
  try {
    bus->Handle(100);
    FAIL();
  } catch (const BusError& e) {
    EXPECT_NE(std::string(e.what()).find("STATUS"), std::string::npos) << e.what();
  }
}

// A watcher that must outlive a bad message gives decode failures to its error callback: Handle() does not
// raise, the good messages after it still arrive.
TEST(MemqBus, ATypedSubscriptionWithAnErrorCallbackOutlivesABadMessage) {
  auto bus = MakeBus("memq://");
  std::vector<std::string> errors, names;
  auto sub = bus->Subscribe(
      channels::kStatus, [&](const status_t& s) { names.push_back(s.name); },
      [&](const std::string& error) { errors.push_back(error); });
  const uint8_t garbage[3] = {1, 2, 3};
  bus->PublishRaw(channels::kStatus.name, garbage, sizeof(garbage));
  bus->Publish(channels::kStatus, MakeStatus("after"));
  EXPECT_NO_THROW(while (bus->Handle(100) > 0){});
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("STATUS"), std::string::npos) << errors[0];
  EXPECT_EQ(names, std::vector<std::string>{"after"});
}

TEST(BusFactory, UnknownUrlsAreRejected) {
  EXPECT_THROW(MakeBus("carrier-pigeon://home"), BusError);
  EXPECT_THROW(MakeBus("no-scheme"), BusError);
}

int64_t ReadRmemMax() {
  std::ifstream in("/proc/sys/net/core/rmem_max");
  int64_t v = 0;
  in >> v;
  return v;
}

// A 6 MB image over UDP multicast on loopback arrives intact. Needs the receive buffer raised
// (`fusecal doctor --fix`, which tools/test runs); fails with the reason otherwise.
TEST(UdpmBus, SixMegabyteMessageArrivesIntact) {
  constexpr int64_t kBuffer = 64 << 20;
  ASSERT_GE(ReadRmemMax(), kBuffer) << "net.core.rmem_max is below 64 MB: large UDP messages would be dropped. Run "
                                       "`sysctl -w net.core.rmem_max=67108864` (or `fusecal doctor --fix` as root).";
  auto bus = MakeBus("udpm://239.255.76.67:7671?ttl=0&recv_buf_size=67108864");
  cv::Mat pixels(1024, 2048, CV_8UC3);
  cv::randu(pixels, 0, 255);
  const image_t sent = MatToImage(pixels, "bgr8", 99);
  ASSERT_GT(sent.data.size(), 6000000u);
  std::vector<uint8_t> received;
  auto sub =
      bus->Subscribe<image_t>("BIG", std::function<void(const image_t&)>([&](const image_t& m) { received = m.data; }));
  bus->Publish("BIG", sent);
  for (int i = 0; i < 30 && received.empty(); ++i) bus->Handle(100);
  ASSERT_EQ(received.size(), sent.data.size()) << "the 6 MB message did not arrive within 3 s";
  EXPECT_TRUE(received == sent.data);
}

// udpm:// is plain LCM: the parameters of a reliable layer of its own are refused, pointing to dds://, and
// LCM's own options are range-checked before LCM sees them.
TEST(UdpmBus, ParametersOfAReliableLayerAndOutOfRangeOptionsAreRefusedByName) {
  const std::pair<const char*, const char*> cases[] = {
      {"udpm://239.255.76.67:7694?ttl=0&reliable=1", "use dds://"},
      {"udpm://239.255.76.67:7694?ttl=0&loss=0.05", "no loss="},
      {"udpm://239.255.76.67:7694?ttl=999", "ttl=999 is not an integer in [0, 255]"},
      {"udpm://239.255.76.67:7694?ttl=0&recv_buf_size=-1", "recv_buf_size=-1"},
  };
  for (const auto& [url, expected] : cases) {
    try {
      MakeBus(url);
      ADD_FAILURE() << url << " was accepted";
    } catch (const BusError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace fusecal
