// The message bus every process talks through (after Drake's DrakeLcmInterface): publish LCM-encoded
// bytes on a channel, subscribe with a handler, dispatch with Handle(timeout). Implementations: LCM
// (udpm://, memq://, file://, tcpq://), Cyclone DDS (dds://, runtime/dds/) and iceoryx shared memory
// (iox://, runtime/iox/); MakeBus lists the URLs. Typed Publish<M>/Subscribe<M> work for every lcm-gen type.
//
// Handlers run inside Handle() on the caller's thread. An exception thrown by a handler is caught at the
// transport boundary and rethrown from Handle(), so that errors are never swallowed inside C callbacks.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "runtime/bus_error.hpp"
#include "runtime/channels.hpp"

namespace fusecal {

// Wall-clock time in microseconds since the epoch (LCM's utime).
int64_t NowUtime();

// One received message: its channel, its bytes, and when the bus received it. `data` is valid only during
// the handler's call (iox:// points into shared memory that is handed back when the handler returns):
// a handler that keeps the bytes copies them.
struct RawMessage {
  const std::string& channel;
  const uint8_t* data;
  size_t size;
  int64_t receive_utime;
};
using RawHandler = std::function<void(const RawMessage&)>;

class Bus;

// Decodes the LCM bytes of a message of type M that came on `channel`; throws BusError naming the type
// and the channel when they do not hold one (wrong type on the channel, truncated).
template <typename M>
void DecodeMessage(const uint8_t* data, size_t size, const std::string& channel, M* message) {
  if (message->decode(data, 0, static_cast<int>(size)) < 0)
    throw BusError("cannot decode a " + std::string(M::getTypeName()) + " on channel " + channel);
}

// Handle returned by Subscribe; Unsubscribe() stops delivery. Safe to call twice, or after the bus
// is gone.
class Subscription {
 public:
  Subscription() = default;
  explicit Subscription(std::function<void()> unsubscribe) : unsubscribe_(std::move(unsubscribe)) {}
  void Unsubscribe() {
    if (unsubscribe_) unsubscribe_();
    unsubscribe_ = nullptr;
  }

 private:
  std::function<void()> unsubscribe_;
};

class Bus {
 public:
  virtual ~Bus() = default;

  // The URL this bus was created from.
  virtual std::string url() const = 0;

  virtual void PublishRaw(const std::string& channel, const void* data, size_t size) = 0;

  // `channel` is a regular expression matched against the whole channel name (as LCM does); plain
  // names of letters, digits and '_' match themselves.
  virtual Subscription SubscribeRaw(const std::string& channel, RawHandler handler) = 0;

  // Waits up to timeout_ms (0: do not wait) for messages and dispatches every message that is
  // queued. Returns the number of messages delivered to handlers (0 on a timeout, and at the end of a
  // replayed log). Rethrows the first exception thrown by a handler.
  virtual int Handle(int timeout_ms) = 0;

  // Messages this bus knows it lost on the way in (gaps in the publishers' sequence numbers, a full
  // reader queue). 0 where the transport cannot tell (LCM). Stages report it in STATUS as bus_dropped.
  virtual uint64_t dropped_messages() const { return 0; }

  template <typename M>
  void Publish(const std::string& channel, const M& message) {
    std::vector<uint8_t> buffer(message.getEncodedSize());
    if (message.encode(buffer.data(), 0, static_cast<int>(buffer.size())) < 0)
      throw BusError("cannot encode message for channel " + channel);
    PublishRaw(channel, buffer.data(), buffer.size());
  }

  // The same on a typed channel (runtime/channels.hpp): the message type is checked at compile time.
  template <typename M>
  void Publish(const Channel<M>& channel, const M& message) {
    Publish<M>(channel.name, message);
  }

  // `handler` is any callable taking (const M&) or (const M&, const RawMessage&); it receives the decoded
  // message. A message that fails to decode (wrong type on the channel, truncated) raises BusError from
  // Handle() naming the channel, or, for a watcher that must outlive a bad message, goes to `on_error`
  // (with what Handle() would have raised) when one is given.
  template <typename M, typename Handler>
  Subscription Subscribe(const std::string& channel, Handler handler,
                         std::function<void(const std::string&)> on_error = nullptr) {
    return SubscribeRaw(channel,
                        [handler = std::move(handler), on_error = std::move(on_error)](const RawMessage& raw) mutable {
                          M message;
                          try {
                            DecodeMessage(raw.data, raw.size, raw.channel, &message);
                          } catch (const BusError& e) {
                            if (!on_error) throw;
                            on_error(e.what());
                            return;
                          }
                          if constexpr (std::is_invocable_v<Handler&, const M&, const RawMessage&>)
                            handler(message, raw);
                          else
                            handler(message);
                        });
  }

  // The same on a pipeline channel: `bus.Subscribe(channels::kStation, [](const station_t& s) {...})`.
  template <typename M, typename Handler>
  Subscription Subscribe(const Channel<M>& channel, Handler handler,
                         std::function<void(const std::string&)> on_error = nullptr) {
    return Subscribe<M>(std::string(channel.name), std::move(handler), std::move(on_error));
  }
};

// Creates the bus named by `url` (empty: DefaultBusUrl()). The schemes it accepts:
//   udpm://GROUP:PORT?ttl=N&recv_buf_size=B  LCM UDP multicast (ttl=0 stays on the host, ttl=1 spans a LAN)
//   memq://                                  LCM in-process queue (tests, `fusecal calibrate`)
//   file://PATH?mode=r|w&speed=X             LCM log read or written as a bus (LCM's log provider)
//   tcpq://HOST:PORT                         LCM over TCP through an `lcm-tcpq` server
//   dds://?domain=N&shm=0|1&depth=N&bulk_depth=N&shm_max=B
//                                            Cyclone DDS, network path or iceoryx shared memory
//                                            (runtime/dds/dds_bus.hpp; only when built with DDS)
//   iox://?depth=N&bulk_depth=N&max=B&self=0|1  iceoryx shared memory on one host, zero-copy reads: handlers
//                                            see the bytes in place (runtime/iox/iox_bus.hpp; needs a
//                                            RouDi; only when built with iceoryx)
// Throws BusError with the reason (and this list of schemes) when the URL is unknown or the transport
// cannot start.
std::unique_ptr<Bus> MakeBus(const std::string& url);

// The default URL when none is given: $LCM_DEFAULT_URL, else loopback multicast with a 64 MB receive
// buffer (large messages are dropped with the kernel default; see `fusecal doctor`).
std::string DefaultBusUrl();

// True when this build has the iceoryx shared-memory bus (iox://).
bool SharedMemoryBusBuilt();

}  // namespace fusecal
