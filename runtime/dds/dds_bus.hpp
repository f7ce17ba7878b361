// Bus over DDS (Eclipse Cyclone DDS): dds://?domain=0&shm=1&depth=64&bulk_depth=8 (shm_max= also).
//
// Every LCM channel is its own DDS topic whose samples (fusecal::lcm_message, fusecal_bytes.idl) carry
// the channel, the publish utime, a per-writer sequence number and the LCM-encoded bytes, so schemas,
// logs and tools stay LCM. Writers are created on the first publish to a channel; readers on
// subscription: a plain channel name gets its reader at once, a regular expression gets readers for
// matching topics as their writers are discovered (DCPSPublication, local writers included).
// Handle delivers what the readers hold merged in publish order (the writers' utime, then sequence).
//
// QoS and what it drops (the consequences, written down):
// - Per channel kind (runtime/channels.hpp; the rules are written at QosFor in dds_bus.cpp): state
//   channels (STATION, motions, EXTRINSIC, FUSED_MOTIONS, CAMERA_INFO, ...) are reliable, `depth` deep
//   (STATION: keep all on the network path), so loss on the link is re-sent; raw frames (CAMERA_IMAGE,
//   LIDAR_SCAN) are best effort, `bulk_depth` deep, so that a slow or distant reader never holds a
//   writer back. Over shared memory a reader queue drops its oldest when full (iceoryx does not
//   enforce RELIABLE). Whatever a reader misses shows as a gap in the writer's sequence numbers:
//   dropped_messages() counts them, and every stage reports the count as `bus_dropped` in STATUS. A raw
//   frame lost this way costs the stationarity detector a sample.
// - Durability: volatile, as LCM: a reader gets what is written after it matched (a restarted stage
//   is given the stations again by `fusecal run`; transient-local would hand it the writer's last
//   sample first, out of order). A new writer waits 250 ms before its first sample so that existing
//   readers know of it (discovery; RouDi connects shared-memory ports every 100 ms): otherwise the
//   first message on a channel is lost. Publishing to a new channel therefore costs 250 ms once.
//
// URL parameters:
//   domain=N      DDS domain id (default 0)
//   shm=0|1       use iceoryx shared memory (default 0). Needs a running RouDi (iox-roudi; `fusecal
//                 run` starts one); without one the bus says so on stderr and uses the network path
//                 (Cyclone would otherwise wait 60 s and abort the process).
//   shm_max=N     with shared memory, messages over N bytes (default just under 4 MiB, the largest
//                 chunk of RouDi's built-in mempools; iceoryx aborts the process on a sample with no
//                 fitting chunk) are sent by a writer with a deadline, which Cyclone keeps on the network
//                 path, with one line on stderr. `fusecal run` sets it from the pools it gives RouDi.
//   depth=N       KEEP_LAST history depth of small channels (default 64, at most 256)
//   bulk_depth=N  KEEP_LAST history depth of raw frames, and of stations on shared memory (default 8)
// The Cyclone configuration is generated (large socket receive buffer, 64 KB datagrams) so that
// 2-6 MB images survive; $CYCLONEDDS_URI, when set, is applied on top of it.
#pragma once

#include <memory>
#include <string>

#include "runtime/bus.hpp"

namespace fusecal {

class DdsBus : public Bus {
 public:
  // Throws BusError for a malformed URL, an unknown parameter, or when DDS cannot start.
  explicit DdsBus(const std::string& url);
  ~DdsBus() override;
  DdsBus(const DdsBus&) = delete;
  DdsBus& operator=(const DdsBus&) = delete;

  std::string url() const override;
  void PublishRaw(const std::string& channel, const void* data, size_t size) override;
  Subscription SubscribeRaw(const std::string& channel, RawHandler handler) override;
  int Handle(int timeout_ms) override;
  uint64_t dropped_messages() const override;

  // Whether shared memory is in use (false when shm=0, or when shm=1 fell back for lack of RouDi).
  bool shared_memory() const;

  struct Impl;

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace fusecal
