// Shared memory for `fusecal run` (a dds://...&shm=1 bus): starts iceoryx's RouDi with pools planned
// from the config, gives the stages a URL whose shm_max matches those pools, keeps the coordinator
// (player, recorder, supervisor) on DDS's network path, and starts RouDi again when it dies.
//
// Why the coordinator stays off shared memory: stopping RouDi terminates every process attached to it,
// and a process cannot attach to a new RouDi. The stages are restarted by the supervisor and are given
// the stations again; the coordinator holds the session and must survive.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "runtime/shared_memory.hpp"

namespace fusecal {

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

  // When our RouDi has exited: starts it again and returns true (every stage attached to the old one
  // must be restarted). False while it runs, or when fusecal did not start it.
  bool RestartIfDead();
  int roudi_restarts() const { return roudi_ ? roudi_->starts() - 1 : 0; }
  pid_t roudi_pid() const { return roudi_ ? roudi_->pid() : -1; }

  void Stop();

 private:
  std::string stage_url_;
  std::string coordinator_url_;
  std::unique_ptr<shm::RoudiProcess> roudi_;
  std::function<void(const std::string&)> event_;
};

}  // namespace fusecal
