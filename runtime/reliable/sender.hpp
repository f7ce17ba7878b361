// The publishing half of the reliable layer: cuts messages into numbered fragments, keeps the recent
// ones (a byte budget) and answers NACKs from them. No I/O: the caller puts what it returns on the bus.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <vector>

#include "runtime/reliable/wire.hpp"

namespace fusecal::reliable {

struct SenderOptions {
  size_t fragment_bytes = 60000;      // payload per fragment: one loopback datagram with LCM's header
  size_t history_bytes = 64u << 20;   // fragments kept for answering NACKs (the newest of each stream always)
  int64_t resend_gap_us = 10000;      // a fragment just sent again is not sent again for NACKs within this
};

// What to put on the bus: fragments on their channel, control messages on kControlChannel.
struct Outgoing {
  std::string channel;
  std::vector<uint8_t> bytes;
};

class ReliableSender {
 public:
  ReliableSender(uint64_t sender_id, SenderOptions options);

  uint64_t id() const { return id_; }

  // The fragments of one message, numbered on from the channel's last.
  std::vector<Outgoing> Publish(const std::string& channel, const uint8_t* data, size_t size, int64_t now_utime);

  // Fragments sent again and SKIPs for what is no longer kept or predates a first contact. NACKs for
  // other senders are ignored (empty).
  std::vector<Outgoing> OnNack(const Nack& nack, int64_t now_utime);

  // The last sequence number of every stream (empty before the first publish).
  std::vector<Outgoing> MakeHeartbeat() const;

  size_t history_bytes() const { return history_bytes_; }
  uint64_t fragments_resent() const { return resent_; }

 private:
  struct Kept {
    std::vector<uint8_t> bytes;  // the encoded fragment
    int64_t publish_utime = 0;
    int64_t last_sent_utime = 0;
  };
  struct Stream {
    uint64_t next_seq = 0;
    std::map<uint64_t, Kept> kept;
  };
  void Keep(const std::string& channel, uint64_t seq, Kept kept);
  void Evict();

  uint64_t id_;
  SenderOptions options_;
  std::map<std::string, Stream> streams_;
  std::deque<std::pair<std::string, uint64_t>> order_;  // kept fragments, oldest first
  size_t history_bytes_ = 0;
  uint64_t resent_ = 0;
};

}  // namespace fusecal::reliable
