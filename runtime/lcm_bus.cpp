#include "runtime/lcm_bus.hpp"

#include <lcm/lcm.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <optional>
#include <random>

#include "runtime/channel_pattern.hpp"
#include "runtime/reliable/lossy_link.hpp"
#include "runtime/reliable/receiver.hpp"
#include "runtime/reliable/sender.hpp"
#include "runtime/reliable/url_options.hpp"
#include "runtime/reliable/wire.hpp"

namespace fusecal {

struct LcmBus::Slot {
  LcmBus* bus = nullptr;
  int id = 0;  // 0: the reliable layer's control channel
  RawHandler handler;
  lcm_subscription_t* subscription = nullptr;
  std::unique_ptr<reliable::ReliableReceiver> receiver;  // reliable udpm:// only
};

namespace {

// LCM keeps 30 messages per subscription by default and drops the rest while a handler is busy;
// stations and bursts of frames need more room, and fragments of the reliable layer more still.
constexpr int kQueueCapacity = 200;
constexpr int kReliableQueueCapacity = 4000;
constexpr int64_t kHeartbeatPeriodUs = 100000;
constexpr int64_t kGapPollPeriodUs = 5000;

void OnLcmMessage(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
  auto* slot = static_cast<LcmBus::Slot*>(user);
  slot->bus->Receive(slot->id, channel, static_cast<const uint8_t*>(rbuf->data), rbuf->data_size, rbuf->recv_utime);
}

uint64_t RandomSenderId() {
  std::random_device device;
  return (uint64_t(device()) << 32) ^ uint64_t(device()) ^ uint64_t(NowUtime());
}

}  // namespace

int64_t NowUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

LcmBus::LcmBus(const std::string& url) : url_(url), alive_(std::make_shared<bool>(true)) {
  std::string lcm_url = url;
  if (url.rfind("udpm://", 0) == 0) {
    try {
      options_ = std::make_unique<reliable::UrlOptions>(reliable::ParseUrlOptions(url));
    } catch (const std::invalid_argument& e) {
      throw BusError(e.what());
    }
    lcm_url = options_->lcm_url;
  }
  lcm_ = lcm_create(lcm_url.c_str());
  if (!lcm_)
    throw BusError("cannot open LCM bus '" + url +
                   "' (unknown provider, bad URL, unreadable log, or no multicast route: run "
                   "`fusecal doctor`)");
  if (!options_) return;
  if (options_->loss > 0 || options_->jitter_us > 0)
    lossy_ = std::make_unique<reliable::LossyLink>(options_->loss, options_->jitter_us, options_->loss_seed);
  if (!options_->reliable) return;
  sender_ = std::make_unique<reliable::ReliableSender>(RandomSenderId(), options_->sender);
  control_slot_ = std::make_unique<Slot>();
  control_slot_->bus = this;
  control_slot_->subscription = lcm_subscribe(lcm_, reliable::kControlChannel, &OnLcmMessage, control_slot_.get());
  if (!control_slot_->subscription) throw BusError("LCM subscribe failed for the reliable layer's control channel");
  lcm_subscription_set_queue_capacity(control_slot_->subscription, kReliableQueueCapacity);
}

LcmBus::~LcmBus() {
  *alive_ = false;
  for (auto& slot : slots_)
    if (slot->subscription) lcm_unsubscribe(lcm_, slot->subscription);
  if (control_slot_) lcm_unsubscribe(lcm_, control_slot_->subscription);
  lcm_destroy(lcm_);
}

void LcmBus::Send(const std::string& channel, const std::vector<uint8_t>& bytes) {
  if (lcm_publish(lcm_, channel.c_str(), bytes.data(), static_cast<unsigned int>(bytes.size())) != 0)
    throw BusError("LCM publish failed on channel " + channel + " (" + std::to_string(bytes.size()) +
                   " bytes) over " + url_);
}

void LcmBus::PublishRaw(const std::string& channel, const void* data, size_t size) {
  if (!sender_) {
    if (lcm_publish(lcm_, channel.c_str(), data, static_cast<unsigned int>(size)) != 0)
      throw BusError("LCM publish failed on channel " + channel + " (" + std::to_string(size) +
                     " bytes) over " + url_);
    return;
  }
  if (channel == reliable::kControlChannel) throw BusError("channel " + channel + " is the bus's own");
  for (const auto& out : sender_->Publish(channel, static_cast<const uint8_t*>(data), size, NowUtime()))
    Send(out.channel, out.bytes);
}

Subscription LcmBus::SubscribeRaw(const std::string& channel, RawHandler handler) {
  auto slot = std::make_unique<Slot>();
  slot->bus = this;
  slot->id = next_slot_id_++;
  slot->handler = std::move(handler);
  if (sender_)
    // HEARTBEATs name every channel of a publisher; the receiver keeps those this subscription matches
    // (LCM's POSIX extended grammar).
    slot->receiver = std::make_unique<reliable::ReliableReceiver>(
        options_->receiver, NowUtime(),
        [pattern = ChannelPattern(channel, "LCM", std::regex::extended)](const std::string& name) {
          return pattern.Matches(name);
        });
  slot->subscription = lcm_subscribe(lcm_, channel.c_str(), &OnLcmMessage, slot.get());
  if (!slot->subscription) throw BusError("LCM subscribe failed for channel " + channel);
  lcm_subscription_set_queue_capacity(slot->subscription, sender_ ? kReliableQueueCapacity : kQueueCapacity);
  const int id = slot->id;
  slots_.push_back(std::move(slot));
  std::weak_ptr<bool> alive = alive_;
  return Subscription([this, id, alive]() {
    if (alive.expired()) return;
    for (auto it = slots_.begin(); it != slots_.end(); ++it) {
      if ((*it)->id != id) continue;
      lcm_unsubscribe(lcm_, (*it)->subscription);
      if ((*it)->receiver) lost_by_gone_slots_ += (*it)->receiver->lost_runs();
      slots_.erase(it);
      return;
    }
  });
}

LcmBus::Slot* LcmBus::FindSlot(int slot_id) {
  for (auto& slot : slots_)
    if (slot->id == slot_id) return slot.get();
  return nullptr;
}

void LcmBus::Receive(int slot_id, const char* channel, const uint8_t* data, size_t size, int64_t recv_utime) {
  if (lossy_) {
    if (!lossy_->Survives(size)) return;
    if (const int64_t delay = lossy_->DelayUs(); delay > 0) {
      held_back_.emplace(NowUtime() + delay, HeldBack{slot_id, channel, std::vector<uint8_t>(data, data + size), recv_utime});
      return;
    }
  }
  Process(slot_id, channel, data, size, recv_utime);
}

void LcmBus::Process(int slot_id, const std::string& channel, const uint8_t* data, size_t size, int64_t recv_utime) {
  if (slot_id == 0) {
    ProcessControl(data, size, NowUtime());
    return;
  }
  if (sender_ && channel == reliable::kControlChannel) return;  // a pattern such as ".*" matched it
  Slot* slot = FindSlot(slot_id);
  if (!slot) return;
  if (!slot->receiver) {
    Deliver(*slot, channel, data, size, recv_utime);
    return;
  }
  std::optional<reliable::FragmentHeader> header;
  try {
    header = reliable::DecodeFragmentHeader(data, size);
  } catch (const std::invalid_argument& e) {
    if (rejected_++ == 0) std::fprintf(stderr, "bus: rejected a message on %s: %s\n", channel.c_str(), e.what());
    return;
  }
  if (!header) {  // a plain LCM publisher: as it comes
    Deliver(*slot, channel, data, size, recv_utime);
    return;
  }
  auto deliveries = slot->receiver->OnFragment(channel, *header, data + reliable::kFragmentHeaderBytes,
                                               size - reliable::kFragmentHeaderBytes, recv_utime);
  for (const auto& d : deliveries)
    if (Slot* s = FindSlot(slot_id)) Deliver(*s, d.channel, d.bytes.data(), d.bytes.size(), d.receive_utime);
}

void LcmBus::ProcessControl(const uint8_t* data, size_t size, int64_t now) {
  reliable::Control control;
  try {
    control = reliable::DecodeControl(data, size);
  } catch (const std::invalid_argument& e) {
    if (rejected_++ == 0) std::fprintf(stderr, "bus: rejected a control message: %s\n", e.what());
    return;
  }
  if (control.nack)
    for (const auto& out : sender_->OnNack(*control.nack, now)) Send(out.channel, out.bytes);
  std::vector<int> ids;
  for (const auto& slot : slots_) ids.push_back(slot->id);
  for (const int id : ids) {
    Slot* slot = FindSlot(id);
    if (!slot || !slot->receiver) continue;
    if (control.heartbeat) slot->receiver->OnHeartbeat(*control.heartbeat, now);
    if (!control.skip) continue;
    for (const auto& d : slot->receiver->OnSkip(*control.skip, now))
      if (Slot* s = FindSlot(id)) Deliver(*s, d.channel, d.bytes.data(), d.bytes.size(), d.receive_utime);
  }
}

void LcmBus::Deliver(Slot& slot, const std::string& channel, const uint8_t* data, size_t size, int64_t recv_utime) {
  ++handled_;
  // Every handler gets the message even when another one failed on it (in one process, a stage that
  // cannot use a station must not keep it from the others); the first error surfaces from Handle().
  try {
    slot.handler(RawMessage{channel, data, size, recv_utime});
  } catch (...) {
    if (!pending_error_) pending_error_ = std::current_exception();
  }
}

void LcmBus::Service(int64_t now) {
  while (!held_back_.empty() && held_back_.begin()->first <= now) {
    HeldBack item = std::move(held_back_.begin()->second);
    held_back_.erase(held_back_.begin());
    Process(item.slot_id, item.channel, item.bytes.data(), item.bytes.size(), item.recv_utime);
  }
  if (!sender_) return;
  std::vector<int> ids;
  for (const auto& slot : slots_) ids.push_back(slot->id);
  for (const int id : ids) {
    Slot* slot = FindSlot(id);
    if (!slot) continue;
    auto poll = slot->receiver->Poll(now);
    for (const auto& nack : poll.nacks) Send(reliable::kControlChannel, reliable::Encode(nack));
    for (const auto& d : poll.deliveries)
      if (Slot* s = FindSlot(id)) Deliver(*s, d.channel, d.bytes.data(), d.bytes.size(), d.receive_utime);
  }
  if (now - last_heartbeat_ >= kHeartbeatPeriodUs) {
    last_heartbeat_ = now;
    for (const auto& out : sender_->MakeHeartbeat()) Send(out.channel, out.bytes);
  }
}

int64_t LcmBus::NextServiceUtime(int64_t now) const {
  int64_t next = INT64_MAX;
  if (!held_back_.empty()) next = held_back_.begin()->first;
  if (!sender_) return next;
  next = std::min(next, last_heartbeat_ + kHeartbeatPeriodUs);
  for (const auto& slot : slots_)
    if (slot->receiver->has_gaps()) return std::min(next, now + kGapPollPeriodUs);
  return next;
}

uint64_t LcmBus::dropped_messages() const {
  uint64_t lost = lost_by_gone_slots_;
  for (const auto& slot : slots_)
    if (slot->receiver) lost += slot->receiver->lost_runs();
  return lost;
}

uint64_t LcmBus::resent_datagrams() const { return sender_ ? sender_->fragments_resent() : 0; }

int LcmBus::Handle(int timeout_ms) {
  handled_ = 0;
  const int64_t deadline = NowUtime() + int64_t(std::max(0, timeout_ms)) * 1000;
  for (;;) {
    const int64_t now = NowUtime();
    Service(now);
    if (handled_ > 0 || pending_error_) break;
    const int64_t wait_us = std::max<int64_t>(0, std::min(deadline, NextServiceUtime(now)) - now);
    // Wait for the first message, then drain whatever else is already queued.
    int status = lcm_handle_timeout(lcm_, int((wait_us + 999) / 1000));
    while (status > 0 && !pending_error_) status = lcm_handle_timeout(lcm_, 0);
    if (status < 0) {
      if (url_.rfind("file://", 0) == 0) break;  // the log is exhausted
      throw BusError("LCM handle failed on " + url_ + " (socket error)");
    }
    if (handled_ > 0 || pending_error_ || NowUtime() >= deadline) {
      if (!pending_error_) Service(NowUtime());
      break;
    }
  }
  if (pending_error_) {
    std::exception_ptr error = pending_error_;
    pending_error_ = nullptr;
    std::rethrow_exception(error);
  }
  return handled_;
}

}  // namespace fusecal
