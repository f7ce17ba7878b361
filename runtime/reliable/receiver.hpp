// The receiving half of the reliable layer, one per subscription: puts each publisher's fragments back
// in order, asks again for the missing ones (NACK), reassembles messages and hands them on in the order
// they were published. No I/O: the caller feeds it what the bus received and sends the NACKs it returns.
//
// A gap is asked for once it has lasted `nack_delay_us` (fragments that are only late, as with jitter,
// are not asked for), then every `nack_retry_us`, until the fragment comes, the publisher says it is
// gone (SKIP), or `give_up_us` has passed without either (the publisher died): then what is missing is
// counted as lost and what follows is delivered. On first contact with a publisher (its first fragment
// seen is not number 0, or a HEARTBEAT names a stream never seen) the receiver asks for everything
// published since it subscribed, so that a message sent before the subscription reached the network
// is not lost either.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "runtime/reliable/wire.hpp"

namespace fusecal::reliable {

struct ReceiverOptions {
  int64_t nack_delay_us = 20000;
  int64_t nack_retry_us = 50000;
  int64_t give_up_us = 10000000;
};

struct Delivery {
  std::string channel;
  std::vector<uint8_t> bytes;
  int64_t receive_utime = 0;  // when its last fragment came
};

class ReliableReceiver {
 public:
  // `subscribed_utime`: when the subscription was made (first contact asks for what came after it);
  // `matches`: whether a channel is this subscription's (HEARTBEATs name every channel of a sender).
  ReliableReceiver(ReceiverOptions options, int64_t subscribed_utime, std::function<bool(const std::string&)> matches);

  std::vector<Delivery> OnFragment(const std::string& channel, const FragmentHeader& header, const uint8_t* payload,
                                   size_t bytes, int64_t now_utime);
  std::vector<Delivery> OnSkip(const Skip& skip, int64_t now_utime);
  void OnHeartbeat(const Heartbeat& heartbeat, int64_t now_utime);

  // NACKs that are due, and what giving up on old gaps lets through.
  struct PollResult {
    std::vector<Nack> nacks;
    std::vector<Delivery> deliveries;
  };
  PollResult Poll(int64_t now_utime);

  bool has_gaps() const;
  uint64_t lost_runs() const { return lost_runs_; }  // each cost at least one message
  uint64_t duplicates() const { return duplicates_; }

 private:
  struct Held {
    FragmentHeader header;
    std::vector<uint8_t> payload;
    int64_t receive_utime = 0;
  };
  struct SkipRange {
    uint64_t to = 0;
    bool lost = false;
  };
  struct Stream {
    std::string channel;
    uint64_t sender = 0;
    uint64_t next = 0;             // the next fragment to hand on
    uint64_t known_last = 0;       // the highest number heard of (a fragment or a HEARTBEAT)
    bool heard = false;
    int64_t contact_last = -1;     // numbers up to this are asked for "since subscribed" (first contact)
    std::map<uint64_t, Held> held;
    std::map<uint64_t, SkipRange> skips;  // from -> range
    int64_t gap_since = 0, last_nack = 0, last_heard = 0;
    // The message being reassembled.
    std::vector<uint8_t> message;
    uint32_t expect_index = 0, count = 0;
    size_t expected_bytes = 0;
  };
  using Key = std::pair<uint64_t, std::string>;

  Stream& StreamFor(uint64_t sender, const std::string& channel, uint64_t seen_seq, bool seen_is_fragment,
                    int64_t now_utime);
  std::vector<Delivery> Drain(Stream& stream);
  void Assemble(Stream& stream, Held& fragment, std::vector<Delivery>* out);
  bool HasGap(const Stream& stream) const;
  std::vector<SeqRange> Missing(const Stream& stream, size_t max_ranges) const;
  void GiveUp(Stream& stream);

  ReceiverOptions options_;
  int64_t subscribed_utime_;
  std::function<bool(const std::string&)> matches_;
  std::map<Key, Stream> streams_;
  uint64_t lost_runs_ = 0, duplicates_ = 0;
};

}  // namespace fusecal::reliable
