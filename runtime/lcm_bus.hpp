// Bus over LCM: udpm:// (multicast, also across machines), memq:// (in-process), file:// (log replay).
#pragma once

#include <exception>
#include <list>
#include <memory>
#include <mutex>

#include "runtime/bus.hpp"

typedef struct _lcm_t lcm_t;

namespace fusecal {

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

  // Called by the C callback; public only for it.
  struct Slot;
  void Deliver(Slot* slot, const char* channel, const void* data, size_t size, int64_t recv_utime);

 private:
  std::string url_;
  lcm_t* lcm_ = nullptr;
  std::list<std::unique_ptr<Slot>> slots_;
  std::shared_ptr<bool> alive_;  // lets Subscription handles outlive the bus safely
  std::exception_ptr pending_error_;
  int handled_ = 0;
};

}  // namespace fusecal
