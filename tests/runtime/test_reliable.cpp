// The reliable layer of udpm:// without a bus: one publisher and its receivers on a simulated network
// that loses, delays and reorders datagrams, in simulated time.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "runtime/reliable/lossy_link.hpp"
#include "runtime/reliable/receiver.hpp"
#include "runtime/reliable/sender.hpp"
#include "runtime/reliable/url_options.hpp"
#include "runtime/reliable/wire.hpp"

namespace fusecal::reliable {
namespace {

std::vector<uint8_t> Pattern(size_t size, int message) {
  std::vector<uint8_t> bytes(size);
  for (size_t i = 0; i < size; ++i) bytes[i] = uint8_t(i * 7 + message * 31);
  return bytes;
}

// A publisher, receivers subscribed at `subscribed_utime`, and datagrams in flight. Every datagram
// (fragment, NACK, SKIP, HEARTBEAT) is lost with probability `loss` and delayed by 0..jitter.
struct SimulatedNetwork {
  SenderOptions sender_options{1000, 64u << 20, 10000};
  ReliableSender sender{42, sender_options};
  std::vector<ReliableReceiver> receivers;
  std::vector<std::vector<Delivery>> delivered;
  double loss = 0;
  int64_t jitter_us = 0;
  int64_t now = 1000000;
  bool sender_alive = true;
  std::mt19937_64 random{7};
  struct InFlight {
    int to;  // -1: the publisher, else a receiver
    Outgoing datagram;
  };
  std::multimap<int64_t, InFlight> in_flight;

  void AddReceiver(int64_t subscribed_utime, ReceiverOptions options = {}) {
    receivers.emplace_back(options, subscribed_utime, [](const std::string& c) { return c == "DATA"; });
    delivered.emplace_back();
  }
  void Send(int to, const Outgoing& datagram) {
    if (std::uniform_real_distribution<double>(0, 1)(random) < loss) return;
    const int64_t delay = jitter_us ? std::uniform_int_distribution<int64_t>(0, jitter_us)(random) : 0;
    in_flight.emplace(now + 1 + delay, InFlight{to, datagram});
  }
  void ToReceivers(const std::vector<Outgoing>& out) {
    for (const auto& datagram : out)
      for (int r = 0; r < int(receivers.size()); ++r) Send(r, datagram);
  }
  void Publish(const std::vector<uint8_t>& message) { ToReceivers(sender.Publish("DATA", message.data(), message.size(), now)); }
  void Keep(int r, std::vector<Delivery> out) {
    for (auto& d : out) delivered[r].push_back(std::move(d));
  }
  void Arrive(const InFlight& item) {
    const auto& bytes = item.datagram.bytes;
    if (item.to < 0) {
      if (!sender_alive) return;
      ToReceivers(sender.OnNack(*DecodeControl(bytes.data(), bytes.size()).nack, now));
      return;
    }
    auto& receiver = receivers[item.to];
    if (item.datagram.channel != kControlChannel) {
      const auto header = DecodeFragmentHeader(bytes.data(), bytes.size());
      Keep(item.to, receiver.OnFragment(item.datagram.channel, *header, bytes.data() + kFragmentHeaderBytes,
                                        bytes.size() - kFragmentHeaderBytes, now));
      return;
    }
    const Control control = DecodeControl(bytes.data(), bytes.size());
    if (control.heartbeat) receiver.OnHeartbeat(*control.heartbeat, now);
    if (control.skip) Keep(item.to, receiver.OnSkip(*control.skip, now));
  }
  // Advances time in 1 ms steps: arrivals, the receivers' polls (NACKs to the publisher), heartbeats.
  void Run(int64_t duration_us) {
    for (const int64_t end = now + duration_us; now < end; now += 1000) {
      while (!in_flight.empty() && in_flight.begin()->first <= now) {
        const InFlight item = in_flight.begin()->second;
        in_flight.erase(in_flight.begin());
        Arrive(item);
      }
      for (int r = 0; r < int(receivers.size()); ++r) {
        auto poll = receivers[r].Poll(now);
        for (const auto& nack : poll.nacks) Send(-1, Outgoing{kControlChannel, Encode(nack)});
        Keep(r, std::move(poll.deliveries));
      }
      if (sender_alive && now % 100000 == 0) ToReceivers(sender.MakeHeartbeat());
    }
  }
};

void ExpectDeliveredInOrder(const std::vector<Delivery>& got, const std::vector<std::vector<uint8_t>>& sent) {
  ASSERT_EQ(got.size(), sent.size());
  for (size_t i = 0; i < sent.size(); ++i) EXPECT_EQ(got[i].bytes, sent[i]) << "message " << i;
}

TEST(ReliableLayer, MessagesOfEverySizeArriveWholeOnALosslessLink) {
  SimulatedNetwork net;
  net.AddReceiver(0);
  std::vector<std::vector<uint8_t>> sent;
  for (size_t size : {0, 1, 999, 1000, 1001, 3500, 20000}) sent.push_back(Pattern(size, int(sent.size())));
  for (const auto& m : sent) net.Publish(m);
  net.Run(50000);
  ExpectDeliveredInOrder(net.delivered[0], sent);
  EXPECT_EQ(net.receivers[0].lost_runs(), 0u);
  EXPECT_EQ(net.sender.fragments_resent(), 0u);
}

TEST(ReliableLayer, TwentyPercentLossAndReorderingStillDeliverEverythingOnceInOrder) {
  SimulatedNetwork net;
  net.loss = 0.2;
  net.jitter_us = 10000;
  net.AddReceiver(0);
  net.AddReceiver(0);
  std::vector<std::vector<uint8_t>> sent;
  for (int m = 0; m < 60; ++m) {
    sent.push_back(Pattern(size_t(m % 7) * 1700 + 3, m));
    net.Publish(sent.back());
    net.Run(3000);
  }
  net.Run(3000000);
  for (int r = 0; r < 2; ++r) {
    ExpectDeliveredInOrder(net.delivered[r], sent);
    EXPECT_EQ(net.receivers[r].lost_runs(), 0u);
  }
  EXPECT_GT(net.sender.fragments_resent(), 10u);  // the loss was real and repaired
}

TEST(ReliableLayer, ALostLastFragmentIsNoticedFromTheHeartbeat) {
  SimulatedNetwork net;
  net.AddReceiver(0);
  net.now += 1000;  // between heartbeats (every 100 ms of simulated time)
  const auto message = Pattern(2500, 1);  // three fragments
  auto fragments = net.sender.Publish("DATA", message.data(), message.size(), net.now);
  ASSERT_EQ(fragments.size(), 3u);
  fragments.pop_back();  // the last one never arrives, and nothing follows it
  net.ToReceivers(fragments);
  net.Run(50000);
  EXPECT_TRUE(net.delivered[0].empty());
  net.Run(300000);  // a heartbeat names fragment 2; it is asked for and sent again
  ExpectDeliveredInOrder(net.delivered[0], {message});
}

TEST(ReliableLayer, FirstContactGetsWhatCameAfterSubscribingAndNotWhatCameBefore) {
  SimulatedNetwork net;
  const auto before = Pattern(10, 0), lost = Pattern(10, 1), seen = Pattern(10, 2);
  net.Publish(before);  // nobody subscribed yet
  net.in_flight.clear();
  net.now += 1000;
  net.AddReceiver(net.now);
  net.now += 1000;
  net.sender.Publish("DATA", lost.data(), lost.size(), net.now);  // published after subscribing, lost
  net.now += 1000;
  net.Publish(seen);
  net.Run(200000);
  ExpectDeliveredInOrder(net.delivered[0], {lost, seen});
  EXPECT_EQ(net.receivers[0].lost_runs(), 0u);
}

TEST(ReliableLayer, WhatThePublisherNoLongerKeepsIsCountedLostAndTheRestFlows) {
  SimulatedNetwork net;
  net.sender = ReliableSender(42, SenderOptions{1000, 3000, 10000});  // keeps three fragments
  net.AddReceiver(0);
  const auto gone = Pattern(500, 0);
  net.sender.Publish("DATA", gone.data(), gone.size(), net.now);  // lost on the way
  std::vector<std::vector<uint8_t>> after;
  for (int m = 1; m <= 5; ++m) {
    after.push_back(Pattern(500, m));
    net.Publish(after.back());
  }
  net.Run(300000);
  ExpectDeliveredInOrder(net.delivered[0], after);
  EXPECT_EQ(net.receivers[0].lost_runs(), 1u);
}

TEST(ReliableLayer, AGapNobodyAnswersIsGivenUpAfterTheTimeout) {
  SimulatedNetwork net;
  net.AddReceiver(0, ReceiverOptions{20000, 50000, 500000});
  const auto lost = Pattern(10, 0), next = Pattern(10, 1);
  net.sender.Publish("DATA", lost.data(), lost.size(), net.now);
  net.Publish(next);
  net.sender_alive = false;  // the publisher died: nobody answers NACKs
  net.Run(300000);
  EXPECT_TRUE(net.delivered[0].empty());
  net.Run(400000);
  ExpectDeliveredInOrder(net.delivered[0], {next});
  EXPECT_EQ(net.receivers[0].lost_runs(), 1u);
}

TEST(ReliableLayer, AnotherReceiversBeforeSkipDoesNotMakeThisOneGiveUp) {
  ReceiverOptions options;
  ReliableReceiver early(options, 100, [](const std::string&) { return true; });
  ReliableSender sender(9, SenderOptions{});
  const auto a = Pattern(10, 0), b = Pattern(10, 1);
  auto fa = sender.Publish("DATA", a.data(), a.size(), 200);
  auto fb = sender.Publish("DATA", b.data(), b.size(), 300);
  const auto hb = DecodeFragmentHeader(fb[0].bytes.data(), fb[0].bytes.size());
  early.OnFragment("DATA", *hb, fb[0].bytes.data() + kFragmentHeaderBytes, 10, 300);  // a was lost
  // A receiver that subscribed at 250 asked since 250 and is told a predates it.
  const auto answer = sender.OnNack(Nack{9, "DATA", 250, {{0, 0}}}, 400);
  ASSERT_FALSE(answer.empty());
  const auto skip = DecodeControl(answer.back().bytes.data(), answer.back().bytes.size());
  ASSERT_TRUE(skip.skip);
  EXPECT_TRUE(early.OnSkip(*skip.skip, 400).empty());  // not for this receiver: a can still come
  const auto ha = DecodeFragmentHeader(fa[0].bytes.data(), fa[0].bytes.size());
  const auto out = early.OnFragment("DATA", *ha, fa[0].bytes.data() + kFragmentHeaderBytes, 10, 500);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].bytes, a);
  EXPECT_EQ(out[1].bytes, b);
}

TEST(ReliableWire, MalformedBytesAreRejectedWithAReason) {
  const uint8_t plain_lcm[64] = {1, 2, 3};
  EXPECT_FALSE(DecodeFragmentHeader(plain_lcm, sizeof plain_lcm));  // no magic: a plain LCM message
  FragmentHeader h{1, 0, 0, 10, 3, 2};                              // index 3 of 2
  auto bad = EncodeFragment(h, nullptr, 0);
  EXPECT_THROW(DecodeFragmentHeader(bad.data(), bad.size()), std::invalid_argument);
  FragmentHeader too_big{1, 0, 0, 4, 0, 1};
  auto payload = Pattern(8, 0);
  bad = EncodeFragment(too_big, payload.data(), payload.size());  // 8 bytes of a 4-byte message
  EXPECT_THROW(DecodeFragmentHeader(bad.data(), bad.size()), std::invalid_argument);
  auto nack = Encode(Nack{1, "DATA", 0, {{0, 5}, {7, 9}}});
  for (size_t cut : {size_t(3), size_t(13), nack.size() - 1})
    EXPECT_THROW(DecodeControl(nack.data(), cut), std::invalid_argument) << cut;
  nack[4] = 99;  // the kind, after the magic
  EXPECT_THROW(DecodeControl(nack.data(), nack.size()), std::invalid_argument);
  // Numbers that would wrap "last + 1" (found by fuzzing: a HEARTBEAT naming 2^64-1 hung the receiver).
  const auto wrapping = Encode(Heartbeat{5, {{"A", ~uint64_t(0)}}});
  EXPECT_THROW(DecodeControl(wrapping.data(), wrapping.size()), std::invalid_argument);
  const auto heartbeat = Encode(Heartbeat{5, {{"A", 3}, {"B", 9}}});
  const auto back = DecodeControl(heartbeat.data(), heartbeat.size());
  ASSERT_TRUE(back.heartbeat);
  EXPECT_EQ(back.heartbeat->last_seq.size(), 2u);
}

TEST(ReliableUrl, OurParametersAreReadAndRemovedBadOnesNamed) {
  const auto o = ParseUrlOptions("udpm://239.255.76.67:7667?ttl=0&loss=0.05&jitter_ms=10&recv_buf_size=1000&fragment_kb=8");
  EXPECT_EQ(o.lcm_url, "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=1000");
  EXPECT_DOUBLE_EQ(o.loss, 0.05);
  EXPECT_EQ(o.jitter_us, 10000);
  EXPECT_EQ(o.sender.fragment_bytes, 8000u);
  EXPECT_TRUE(o.reliable);
  EXPECT_FALSE(ParseUrlOptions("udpm://239.255.76.67:7667?reliable=0").reliable);
  for (const char* bad : {"udpm://x?loss=abc", "udpm://x?loss=0.9", "udpm://x?reliable=2", "udpm://x?fragment_kb=0",
                          "udpm://x?jitter_ms=-1", "udpm://x?history_mb=nan"}) {
    try {
      ParseUrlOptions(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("bus URL parameter"), std::string::npos) << e.what();
    }
  }
}

TEST(LossyLink, LosesWholeMessagesAsOftenAsTheirDatagramsSay) {
  LossyLink link(0.05, 0, 3);
  int small = 0, large = 0;
  for (int i = 0; i < 4000; ++i) {
    small += link.Survives(1000);
    large += link.Survives(2000000);  // 31 datagrams: 0.95^31 = 20 % arrive
  }
  EXPECT_NEAR(small / 4000.0, 0.95, 0.02);
  EXPECT_NEAR(large / 4000.0, 0.204, 0.03);
}

}  // namespace
}  // namespace fusecal::reliable
