// Bus over LCM: udpm:// (multicast, also across machines), memq:// (in-process), file:// (log replay),
// tcpq:// (through an lcm-tcpq server).
//
// On udpm:// the bus is reliable by default (runtime/reliable/: fragments, NACKs, re-sending; the
// parameters are in runtime/reliable/url_options.hpp): every message a subscriber was there for
// arrives, once, in the order its publisher sent it, while the publisher keeps it (history_mb) and is
// alive (give_up_s). Messages from plain LCM publishers (no fragment header) are delivered as they
// come. The other providers are lossless already and carry plain LCM.
#pragma once

#include <exception>
#include <list>
#include <map>
#include <memory>
#include <mutex>

#include "runtime/bus.hpp"

typedef struct _lcm_t lcm_t;
typedef struct _lcm_subscription_t lcm_subscription_t;

namespace fusecal {

namespace reliable {
class ReliableSender;
class LossyLink;
struct UrlOptions;
}  // namespace reliable

class LcmBus : public Bus {
 public:
  explicit LcmBus(const std::string& url);
  ~LcmBus() override;
  LcmBus(const LcmBus&) = delete;
  LcmBus& operator=(const LcmBus&) = delete;

  std::string url() const override { return url_; }
  void PublishRaw(const std::string& channel, const void* data, size_t size) override;
  Subscription SubscribeRaw(const std::string& channel, RawHandler handler) override;
  int Handle(int timeout_ms) override;
  // Reliable udpm://: gaps given up on or skipped by their publisher (each at least one message).
  uint64_t dropped_messages() const override;
  uint64_t resent_datagrams() const override;

  bool reliable() const { return sender_ != nullptr; }

  // Called by the C callback; public only for it.
  struct Slot;
  void Receive(int slot_id, const char* channel, const uint8_t* data, size_t size, int64_t recv_utime);

 private:
  void Process(int slot_id, const std::string& channel, const uint8_t* data, size_t size, int64_t recv_utime);
  void ProcessControl(const uint8_t* data, size_t size, int64_t now);
  void Deliver(Slot& slot, const std::string& channel, const uint8_t* data, size_t size, int64_t recv_utime);
  void Service(int64_t now);  // held-back messages that are due, NACKs, heartbeats
  int64_t NextServiceUtime(int64_t now) const;
  void Send(const std::string& channel, const std::vector<uint8_t>& bytes);
  Slot* FindSlot(int slot_id);

  std::string url_;
  lcm_t* lcm_ = nullptr;
  std::list<std::unique_ptr<Slot>> slots_;
  int next_slot_id_ = 1;
  std::shared_ptr<bool> alive_;  // lets Subscription handles outlive the bus safely
  std::exception_ptr pending_error_;
  int handled_ = 0;

  std::unique_ptr<reliable::UrlOptions> options_;
  std::unique_ptr<reliable::ReliableSender> sender_;   // reliable udpm:// only
  std::unique_ptr<reliable::LossyLink> lossy_;         // loss= / jitter_ms= only
  struct HeldBack {
    int slot_id;
    std::string channel;
    std::vector<uint8_t> bytes;
    int64_t recv_utime;
  };
  std::multimap<int64_t, HeldBack> held_back_;  // by due utime (jitter)
  int64_t last_heartbeat_ = 0;
  uint64_t rejected_ = 0;            // malformed fragments or control messages
  uint64_t lost_by_gone_slots_ = 0;  // dropped_messages() of receivers that were unsubscribed
  std::unique_ptr<Slot> control_slot_;
};

}  // namespace fusecal
