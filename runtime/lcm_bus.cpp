#include "runtime/lcm_bus.hpp"

#include <lcm/lcm.h>
#include <poll.h>

#include <chrono>

namespace fusecal {

struct LcmBus::Slot {
  LcmBus* bus;
  RawHandler handler;
  lcm_subscription_t* subscription = nullptr;
};

namespace {

constexpr int kQueueCapacity = 200;

void OnLcmMessage(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
  auto* slot = static_cast<LcmBus::Slot*>(user);
  slot->bus->Deliver(slot, channel, rbuf->data, rbuf->data_size, rbuf->recv_utime);
}

}  // namespace

int64_t NowUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

LcmBus::LcmBus(const std::string& url) : url_(url), alive_(std::make_shared<bool>(true)) {
  lcm_ = lcm_create(url.c_str());
  if (!lcm_)
    throw BusError("cannot open LCM bus '" + url +
                   "' (unknown provider, bad URL, unreadable log, or no multicast route: run "
                   "`fusecal doctor`)");
}

LcmBus::~LcmBus() {
  *alive_ = false;
  for (auto& slot : slots_)
    if (slot->subscription) lcm_unsubscribe(lcm_, slot->subscription);
  lcm_destroy(lcm_);
}

void LcmBus::PublishRaw(const std::string& channel, const void* data, size_t size) {
  if (lcm_publish(lcm_, channel.c_str(), data, static_cast<unsigned int>(size)) != 0)
    throw BusError("LCM publish failed on channel " + channel + " (" + std::to_string(size) +
                   " bytes) over " + url_);
}

Subscription LcmBus::SubscribeRaw(const std::string& channel, RawHandler handler) {
  auto slot = std::make_unique<Slot>();
  slot->bus = this;
  slot->handler = std::move(handler);
  slot->subscription = lcm_subscribe(lcm_, channel.c_str(), &OnLcmMessage, slot.get());
  if (!slot->subscription) throw BusError("LCM subscribe failed for channel " + channel);
  // LCM keeps 30 messages per subscription by default and drops the rest while a handler is busy;
  // stations and bursts of frames need more room.
  lcm_subscription_set_queue_capacity(slot->subscription, kQueueCapacity);
  Slot* raw_slot = slot.get();
  slots_.push_back(std::move(slot));
  std::weak_ptr<bool> alive = alive_;
  return Subscription([this, raw_slot, alive]() {
    if (alive.expired()) return;
    for (auto it = slots_.begin(); it != slots_.end(); ++it) {
      if (it->get() != raw_slot) continue;
      lcm_unsubscribe(lcm_, raw_slot->subscription);
      slots_.erase(it);
      return;
    }
  });
}

void LcmBus::Deliver(Slot* slot, const char* channel, const void* data, size_t size,
                     int64_t recv_utime) {
  ++handled_;
  // Every handler gets the message even when another one failed on it (in one process, a stage that
  // cannot use a station must not keep it from the others); the first error surfaces from Handle().
  try {
    const std::string channel_name(channel);
    slot->handler(RawMessage{channel_name, static_cast<const uint8_t*>(data), size, recv_utime});
  } catch (...) {
    if (!pending_error_) pending_error_ = std::current_exception();
  }
}

int LcmBus::Handle(int timeout_ms) {
  handled_ = 0;
  // Wait for the first message, then drain whatever else is already queued.
  int status = lcm_handle_timeout(lcm_, timeout_ms < 0 ? 0 : timeout_ms);
  while (status > 0 && !pending_error_) status = lcm_handle_timeout(lcm_, 0);
  if (pending_error_) {
    std::exception_ptr error = pending_error_;
    pending_error_ = nullptr;
    std::rethrow_exception(error);
  }
  if (status < 0) {
    if (url_.rfind("file://", 0) == 0) return handled_;  // the log is exhausted
    throw BusError("LCM handle failed on " + url_ + " (socket error)");
  }
  return handled_;
}

}  // namespace fusecal
