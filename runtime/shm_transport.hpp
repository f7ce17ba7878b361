// Shared memory for `fusecal run` (a dds://...&shm=1 or an iox:// bus): starts iceoryx's RouDi with pools
// planned from the config, gives the stages a URL whose shm_max= (dds) or max= (iox) matches those pools,
// keeps the coordinator (player, recorder, supervisor) off shared memory, and starts RouDi again when it
// dies.
//
// Why the coordinator stays off shared memory: stopping RouDi terminates every process attached to it,
// and a process cannot attach to a new RouDi. The stages are restarted by the supervisor and are given
// the stations again; the coordinator holds the session and must survive.
// - dds://...&shm=1: the coordinator uses DDS's network path (shm=0) on the same domain.
// - iox://: iceoryx has no other path, so the coordinator is on LCM multicast on this host
//   (kIoxCoordinatorUrl) and a bridge process (fusecal-bus-bridge, runtime/bus_bridge.hpp) forwards
//   between it and the stages' iox:// bus. The bridge is attached to RouDi like a stage and is restarted
//   with them. The stages talk to each other zero-copy; only what the coordinator sends or reads (the
//   stations of a replayed log, motions, STATUS, EXTRINSIC) crosses the bridge.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "runtime/shared_memory.hpp"

namespace fusecal {

// The coordinator's bus of an iox:// run: LCM multicast that stays on this host, on a port of its own.
inline constexpr const char* kIoxCoordinatorUrl = "udpm://239.255.76.67:7689?ttl=0&recv_buf_size=67108864";

class SharedMemoryTransport {
 public:
  // RouDi's pools hold `chunks` messages of up to `max_message_bytes` (bus.max_message_mb, bus.shm_chunks).
  // For a URL without shm=1 nothing is started and both URLs are `url`. When shared memory cannot be had
  // (no iox-roudi, /dev/shm too small, RouDi failing), `event` says why and the stages use the network
  // path (shm=0): the run goes on.
  SharedMemoryTransport(const std::string& url, size_t max_message_bytes, int chunks, const std::string& out_dir,
                        const std::function<void(const std::string&)>& event);
  ~SharedMemoryTransport();

  const std::string& stage_url() const { return stage_url_; }
  const std::string& coordinator_url() const { return coordinator_url_; }
  bool active() const { return roudi_ != nullptr; }
  // Whether the stages' bus differs from the coordinator's and needs fusecal-bus-bridge between them.
  bool needs_bridge() const { return needs_bridge_; }

  // When our RouDi has exited: starts it again and returns true (every stage attached to the old one
  // must be restarted). False while it runs, or when fusecal did not start it.
  bool RestartIfDead();
  int roudi_restarts() const { return roudi_ ? roudi_->starts() - 1 : 0; }
  pid_t roudi_pid() const { return roudi_ ? roudi_->pid() : -1; }

  void Stop();

 private:
  std::string stage_url_;
  std::string coordinator_url_;
  bool needs_bridge_ = false;
  std::unique_ptr<shm::RoudiProcess> roudi_;
  std::function<void(const std::string&)> event_;
};

}  // namespace fusecal
