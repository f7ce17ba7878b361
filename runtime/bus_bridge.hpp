// Forwards every message between two buses of one host, both ways, without echoing: what `fusecal run`
// puts between the coordinator's bus (LCM, which survives RouDi) and the stages' iox:// bus (see
// runtime/shm_transport.hpp). Runs in a process of its own (fusecal-bus-bridge), which the supervisor
// restarts with the stages when RouDi dies.
//
// Loops: the stage side must not deliver the bridge's own messages back to it (iox:// with self=0). The
// coordinator side (LCM multicast) does deliver them: the bridge remembers what it forwarded there
// (channel, size, hash of the bytes) and drops the first copy that comes back within 5 s. A message the
// coordinator itself publishes with exactly the same bytes on the same channel within that time would be
// taken for the echo and not forwarded; the pipeline publishes no such pair (resupplied stations come
// long after the originals).
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "runtime/bus.hpp"

namespace fusecal {

class BusBridge {
 public:
  // Subscribes on both buses: the pipeline's channels (runtime/channels.hpp) by name, so that the stage
  // side has their subscribers at once (a publisher's first message reaches only the subscribers that
  // exist), and every other channel by pattern.
  BusBridge(Bus& coordinator, Bus& stages);

  // Handles both buses for about `timeout_ms`; returns the messages forwarded.
  int Pump(int timeout_ms);

  uint64_t forwarded_to_stages() const { return to_stages_; }
  uint64_t forwarded_to_coordinator() const { return to_coordinator_; }

 private:
  struct Sent {
    std::string channel;
    size_t size;
    uint64_t hash;
    std::chrono::steady_clock::time_point at;
  };
  void FromCoordinator(const RawMessage& message);
  void FromStages(const RawMessage& message);

  Bus& coordinator_;
  Bus& stages_;
  std::deque<Sent> echoes_;  // forwarded to the coordinator side, not yet seen coming back
  std::vector<Subscription> subscriptions_;
  uint64_t to_stages_ = 0, to_coordinator_ = 0;
};

}  // namespace fusecal
