#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <fstream>

#include "fusecal/image_t.hpp"
#include "fusecal/status_t.hpp"
#include "runtime/bus.hpp"
#include "formats/conversions.hpp"
#include "support/sample_messages.hpp"

namespace fusecal {
namespace {

using testing_utils::MakeStatus;

TEST(MemqBus, TypedRoundTrip) {
  auto bus = MakeBus("memq://");
  std::vector<status_t> received;
  auto sub = bus->Subscribe<status_t>("STATUS", std::function<void(const status_t&)>(
                                                    [&](const status_t& m) { received.push_back(m); }));
  bus->Publish("STATUS", MakeStatus("probe"));
  bus->Publish("OTHER", MakeStatus("ignored"));
  EXPECT_EQ(bus->Handle(100), 1);  // OTHER has no subscriber
  ASSERT_EQ(received.size(), 1u);
  EXPECT_EQ(received[0].name, "probe");
  EXPECT_EQ(received[0].counter_values[0], 4);
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
  ASSERT_GE(ReadRmemMax(), kBuffer)
      << "net.core.rmem_max is below 64 MB: large UDP messages would be dropped. Run "
         "`sysctl -w net.core.rmem_max=67108864` (or `fusecal doctor --fix` as root).";
  auto bus = MakeBus("udpm://239.255.76.67:7671?ttl=0&recv_buf_size=67108864");
  cv::Mat pixels(1024, 2048, CV_8UC3);
  cv::randu(pixels, 0, 255);
  const image_t sent = MatToImage(pixels, "bgr8", 99);
  ASSERT_GT(sent.data.size(), 6000000u);
  std::vector<uint8_t> received;
  auto sub = bus->Subscribe<image_t>("BIG", std::function<void(const image_t&)>(
                                                [&](const image_t& m) { received = m.data; }));
  bus->Publish("BIG", sent);
  for (int i = 0; i < 30 && received.empty(); ++i) bus->Handle(100);
  ASSERT_EQ(received.size(), sent.data.size()) << "the 6 MB message did not arrive within 3 s";
  EXPECT_TRUE(received == sent.data);
}

// The reliable layer of udpm:// (runtime/reliable/) against loss injected on both buses (5 % of the
// datagrams, up to 10 ms of jitter): what `tc netem loss 5% delay 10ms 10ms` does on loopback.
constexpr const char* kLossy = "?ttl=0&recv_buf_size=67108864&loss=0.05&jitter_ms=10";

struct Exchange {
  std::vector<std::vector<uint8_t>> sent, received;
  uint64_t dropped = 0;
};

// `count` messages alternating 200 bytes and 2 MB from one bus to another, both handled in turn
// (the publisher answers NACKs in its Handle) until all came or `seconds` passed.
Exchange SendAcross(const std::string& publisher_url, const std::string& subscriber_url, int count, double seconds) {
  auto publisher = MakeBus(publisher_url);
  auto subscriber = MakeBus(subscriber_url);
  Exchange x;
  auto sub = subscriber->SubscribeRaw("LOSSY_.*", [&](const RawMessage& m) { x.received.emplace_back(m.data, m.data + m.size); });
  for (int i = 0; i < count; ++i) {
    std::vector<uint8_t> message(i % 2 ? 2000000 : 200);
    for (size_t k = 0; k < message.size(); k += 997) message[k] = uint8_t(i + k);
    x.sent.push_back(message);
    publisher->PublishRaw(i % 3 ? "LOSSY_A" : "LOSSY_B", message.data(), message.size());
    publisher->Handle(1);
    subscriber->Handle(5);
  }
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (x.received.size() < x.sent.size() && std::chrono::steady_clock::now() < end) {
    publisher->Handle(2);
    subscriber->Handle(5);
  }
  x.dropped = subscriber->dropped_messages();
  return x;
}

TEST(UdpmBus, TheReliableLayerDeliversEverythingOnceInOrderThroughLossAndJitter) {
  const std::string url = std::string("udpm://239.255.76.67:7691") + kLossy;
  const Exchange x = SendAcross(url, url, 30, 20);
  ASSERT_EQ(x.received.size(), x.sent.size()) << "not everything arrived within 20 s";
  // One subscription, two channels: each publisher's order holds per channel; compare per channel.
  std::vector<std::vector<uint8_t>> a_sent, a_got;
  for (size_t i = 0; i < x.sent.size(); ++i)
    if (i % 3) a_sent.push_back(x.sent[i]);
  for (const auto& m : x.received)
    if (std::find(a_sent.begin(), a_sent.end(), m) != a_sent.end()) a_got.push_back(m);
  EXPECT_EQ(a_got, a_sent);
  EXPECT_EQ(x.dropped, 0u);
}

TEST(UdpmBus, WithoutTheReliableLayerTheSameLossLosesMessages) {
  const std::string url = std::string("udpm://239.255.76.67:7692") + kLossy + "&reliable=0";
  const Exchange x = SendAcross(url, url, 30, 3);
  // A 2 MB message is ~31 datagrams: it arrives whole with 0.95^31 = 20 %.
  EXPECT_LT(x.received.size(), x.sent.size());
  EXPECT_GT(x.received.size(), 0u);
}

TEST(UdpmBus, PlainLcmPublishersAreHeardByAReliableBus) {
  const Exchange x = SendAcross("udpm://239.255.76.67:7693?ttl=0&recv_buf_size=67108864&reliable=0",
                                "udpm://239.255.76.67:7693?ttl=0&recv_buf_size=67108864", 4, 3);
  EXPECT_EQ(x.received, x.sent);
}

TEST(UdpmBus, BadReliabilityParametersAreNamed) {
  for (const char* bad : {"udpm://239.255.76.67:7694?ttl=0&loss=2", "udpm://239.255.76.67:7694?ttl=0&reliable=yes"}) {
    try {
      MakeBus(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const BusError& e) {
      EXPECT_NE(std::string(e.what()).find("bus URL parameter"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace fusecal
