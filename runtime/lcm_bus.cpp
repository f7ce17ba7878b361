#include "runtime/lcm_bus.hpp"

#include <cerrno>
#include <cstring>

#include <lcm/lcm.h>

#include <algorithm>
#include <chrono>
#include <sstream>

#include "runtime/bus_url.hpp"
#include "runtime/channel_pattern.hpp"

namespace fusecal {

struct LcmBus::Slot {
  LcmBus* bus = nullptr;
  int id = 0;
  ChannelPattern pattern;
  RawHandler handler;
  lcm_subscription_t* subscription = nullptr;
};

namespace {

// LCM keeps 30 messages per subscription by default and drops the rest while a handler is busy;
// stations and bursts of frames need more room.
constexpr int kQueueCapacity = 200;

void OnLcmMessage(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
  auto* slot = static_cast<LcmBus::Slot*>(user);
  slot->bus->Deliver(*slot, channel, static_cast<const uint8_t*>(rbuf->data), rbuf->data_size, rbuf->recv_utime);
}

}  // namespace

int64_t NowUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

LcmBus::LcmBus(const std::string& url) : url_(url), alive_(std::make_shared<bool>(true)) {
  ParseBusUrl(url);  // options and ranges, before LCM sees the URL
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
    throw BusError("LCM publish failed on channel " + channel + " (" + std::to_string(size) + " bytes) over " + url_);
}

Subscription LcmBus::SubscribeRaw(const std::string& channel, RawHandler handler) {
  // A pattern is matched here (RE2), never by LCM's own regex engine: LCM hears every channel for it.
  auto slot =
      std::make_unique<Slot>(Slot{this, next_slot_id_++, ChannelPattern(channel, "LCM subscribe"), std::move(handler)});
  const std::string lcm_channel = slot->pattern.plain() ? channel : ".*";
  slot->subscription = lcm_subscribe(lcm_, lcm_channel.c_str(), &OnLcmMessage, slot.get());
  if (!slot->subscription) throw BusError("LCM subscribe failed for channel " + channel);
  lcm_subscription_set_queue_capacity(slot->subscription, kQueueCapacity);
  const int id = slot->id;
  slots_.push_back(std::move(slot));
  std::weak_ptr<bool> alive = alive_;
  return Subscription([this, id, alive]() {
    if (alive.expired()) return;
    for (auto it = slots_.begin(); it != slots_.end(); ++it) {
      if ((*it)->id != id) continue;
      lcm_unsubscribe(lcm_, (*it)->subscription);
      slots_.erase(it);
      return;
    }
  });
}

void LcmBus::Deliver(Slot& slot, const char* channel, const uint8_t* data, size_t size, int64_t recv_utime) {
  const std::string name = channel;
  if (!slot.pattern.Matches(name)) return;  // a pattern's slot hears every channel (SubscribeRaw)
  ++handled_;
  // Every handler gets the message even when another one failed on it (in one process, a stage that
  // cannot use a station must not keep it from the others); the first error surfaces from Handle().
  try {
    slot.handler(RawMessage{name, data, size, recv_utime});
  } catch (...) {
    if (!pending_error_) pending_error_ = std::current_exception();
  }
}

int LcmBus::Handle(int timeout_ms) {
  handled_ = 0;
  // Wait for the first message, then drain whatever else is already queued.
  errno = 0;
  int status = lcm_handle_timeout(lcm_, std::max(0, timeout_ms));
  while (status > 0 && !pending_error_) status = lcm_handle_timeout(lcm_, 0);
  // A signal (Ctrl-C) interrupting the wait is not a socket error; file://: the log is exhausted.
  if (status < 0 && errno != EINTR && url_.rfind("file://", 0) != 0)
    throw BusError("LCM handle failed on " + url_ +
                   " (socket error: " + (errno ? std::string(std::strerror(errno)) : std::string("unknown")) + ")");
  if (pending_error_) {
    std::exception_ptr error = pending_error_;
    pending_error_ = nullptr;
    std::rethrow_exception(error);
  }
  return handled_;
}

}  // namespace fusecal
