// Bus over LCM: udpm:// (multicast, also across machines), memq:// (in-process), file:// (log replay),
// tcpq:// (through an lcm-tcpq server).
//
// What travels is plain LCM: every message is an ordinary LCM message on its channel, whatever its size
// (LCM fragments large ones itself), so lcm-logger, lcm-spy and lcm-logplayer work with a running
// pipeline. UDP multicast is best effort: a datagram the kernel drops loses its message. Lossy or routed
// links and several hosts are what dds:// is for (reliable QoS, runtime/dds/dds_bus.hpp).
#pragma once

#include <exception>
#include <list>
#include <memory>

#include "runtime/bus.hpp"

typedef struct _lcm_t lcm_t;
typedef struct _lcm_subscription_t lcm_subscription_t;

namespace fusecal {

class LcmBus : public Bus {
 public:
  // Throws BusError for a URL LCM cannot open, and for udpm:// parameters out of range.
  explicit LcmBus(const std::string& url);
  ~LcmBus() override;
  LcmBus(const LcmBus&) = delete;
  LcmBus& operator=(const LcmBus&) = delete;

  std::string url() const override { return url_; }
  void PublishRaw(const std::string& channel, const void* data, size_t size) override;
  Subscription SubscribeRaw(const std::string& channel, RawHandler handler) override;
  int Handle(int timeout_ms) override;

  // Called by the C callback; public only for it.
  struct Slot;
  void Deliver(Slot& slot, const char* channel, const uint8_t* data, size_t size, int64_t recv_utime);

 private:
  std::string url_;
  lcm_t* lcm_ = nullptr;
  std::list<std::unique_ptr<Slot>> slots_;
  int next_slot_id_ = 1;
  std::shared_ptr<bool> alive_;  // lets Subscription handles outlive the bus safely
  std::exception_ptr pending_error_;
  int handled_ = 0;
};

}  // namespace fusecal
