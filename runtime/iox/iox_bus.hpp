// Bus over iceoryx shared memory, zero-copy on the way out: iox://?depth=64&bulk_depth=16&max=N
//
// Every LCM channel is an iceoryx service {"fusecal", <channel>, "lcm"} (a channel name is at most 100
// bytes, iceoryx's IdString). A chunk is a small header (IoxChunkHeader: origin, per-publisher sequence
// number, publish utime, size) followed by the LCM bytes. PublishRaw loans a chunk, copies the bytes in
// once and publishes it; Handle() hands each handler a RawMessage whose `data` points into the shared-
// memory chunk itself, valid for the handler's call only (a stage that keeps the message copies it, as
// every decoding handler does). A handler that looks only at the first bytes never touches the rest.
// What several subscribers hold is delivered merged in publish order (utime, then sequence).
//
// Subscriptions: a plain channel name gets its subscriber at once; a regular expression gets subscribers
// for the matching services as iceoryx's service discovery reports them (polled every 100 ms while
// Handle() waits, and on every SubscribeRaw).
//
// What it keeps and drops (the consequences, written down):
// - Volatile, as LCM: a subscriber gets what is published after RouDi connected it (RouDi connects
//   ports every 100 ms). A new publisher therefore waits up to 250 ms on its first message until it has
//   a subscriber, so that the first message on a channel is not lost; a channel nobody reads costs
//   250 ms once.
// - A publisher never blocks: a subscriber queue holds `bulk_depth` chunks on the large channels of
//   runtime/channels.hpp (CAMERA_IMAGE, LIDAR_SCAN, STATION) and `depth` on the others, and drops its
//   oldest when full. The subscriber sees a gap in the publisher's sequence numbers: dropped_messages()
//   counts it (stages report it as bus_dropped).
//   With the defaults a subscriber that reads 20 ms of every 100 ms loses nothing at 30 Hz.
// - Every queued chunk holds a chunk of RouDi's pools: the pools (shm::PlanPools, which `fusecal run`
//   gives RouDi) need bulk_depth chunks per reader of a bulk channel, plus one per publisher.
//
// URL parameters:
//   depth=N       subscriber queue of small channels (default 64, at most 256, iceoryx's limit)
//   bulk_depth=N  subscriber queue of image, scan and station channels (default 16, at most 256)
//   max=N         the largest message in bytes (default just under 4 MiB, the largest chunk of RouDi's
//                 built-in pools; `fusecal run` sets it from the pools it plans). A larger message is
//                 refused with a BusError naming both sizes, and so is one larger than the biggest pool of
//                 the running RouDi (read from its config file): iceoryx would abort the process on a
//                 chunk no pool holds.
//   self=0|1      deliver the messages this bus published itself to its own handlers (default 1, as LCM
//                 does; the bridge of `fusecal run` uses 0)
// Needs a running RouDi (iox-roudi; `fusecal run` starts one): without one the constructor throws a
// BusError at once (iceoryx would wait for RouDi and then abort). iceoryx registers a process with RouDi
// once: every IoxBus of a process shares that registration, and a process whose RouDi died cannot attach
// to a new one (it must be restarted, see runtime/shm_transport.hpp).
#pragma once

#include <memory>
#include <string>

#include "runtime/bus.hpp"

namespace fusecal {

class IoxBus : public Bus {
 public:
  // Throws BusError for a malformed URL, an unknown parameter, or when no RouDi runs.
  explicit IoxBus(const std::string& url);
  ~IoxBus() override;
  IoxBus(const IoxBus&) = delete;
  IoxBus& operator=(const IoxBus&) = delete;

  std::string url() const override;
  void PublishRaw(const std::string& channel, const void* data, size_t size) override;
  Subscription SubscribeRaw(const std::string& channel, RawHandler handler) override;
  int Handle(int timeout_ms) override;
  uint64_t dropped_messages() const override;

  struct Impl;

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace fusecal
