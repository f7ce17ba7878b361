// Bus over DDS (Eclipse Cyclone DDS): dds://?domain=0&shm=1&depth=16 (shm_max= also).
//
// Every LCM channel is its own DDS topic whose samples (fusecal::lcm_message, fusecal_bytes.idl) carry
// the channel, the publish utime and the LCM-encoded bytes, so schemas, logs and tools stay LCM.
// QoS: reliable, volatile, KEEP_LAST `depth` (default 16). Writers are created on the first publish
// to a channel; readers on subscription: a plain channel name gets its reader at once, a regular
// expression gets readers for matching topics as their writers are discovered (DCPSPublication,
// local writers included). As with LCM, messages sent before a reader exists are not delivered.
//
// URL parameters:
//   domain=N   DDS domain id (default 0)
//   shm=0|1    use iceoryx shared memory (default 0). Needs a running RouDi (iox-roudi); without one
//              the bus says so on stderr and uses the network path (Cyclone would otherwise wait 60 s
//              and abort the process).
//   shm_max=N  with shared memory, messages over N bytes (default just under 4 MiB, the largest chunk
//              of RouDi's built-in mempools; iceoryx aborts the process on a sample with no fitting
//              chunk) are sent by a KEEP_ALL writer, which Cyclone keeps on the network path. Raise it
//              only together with RouDi's mempool configuration (roudi_config.toml).
//   depth=N    KEEP_LAST history depth per channel (default 16)
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

  // Whether shared memory is in use (false when shm=0, or when shm=1 fell back for lack of RouDi).
  bool shared_memory() const;

  // Whether an iceoryx RouDi daemon answers on this machine.
  static bool RoudiRunning();

  struct Impl;

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace fusecal
