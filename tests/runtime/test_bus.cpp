#include <gtest/gtest.h>

#include <fstream>

#include "fusecal/image_t.hpp"
#include "fusecal/status_t.hpp"
#include "runtime/bus.hpp"
#include "formats/conversions.hpp"
#include "sample_messages.hpp"

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

}  // namespace
}  // namespace fusecal
