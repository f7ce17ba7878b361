#include "runtime/shm_transport.hpp"

#include <stdexcept>

#include "runtime/bus_url.hpp"

namespace fusecal {

SharedMemoryTransport::SharedMemoryTransport(const std::string& url, size_t max_message_bytes, int chunks,
                                             const std::string& out_dir,
                                             const std::function<void(const std::string&)>& event)
    : stage_url_(url), coordinator_url_(url), event_(event) {
  const bool iox = IsIoxUrl(url);
  if (!IsSharedMemoryDdsUrl(url) && !iox) return;
  const std::string max_key = iox ? "max" : "shm_max";
  coordinator_url_ = iox ? kIoxCoordinatorUrl : WithUrlParameter(url, "shm", "0");
  needs_bridge_ = iox;
  if (!shm::WaitUntilRoudiGone(2)) {  // (one stopped just now takes a moment to go)
    event_(
        "shared memory: a RouDi that fusecal did not start is running; the stages use it (its pools must "
        "hold messages up to " +
        max_key + "=" +
        (UrlParameter(url, max_key).empty() ? std::string("4 MiB, the default") : UrlParameter(url, max_key)) +
        "), and fusecal cannot restart it");
    return;
  }
  const shm::PoolPlan plan = shm::PlanPools(max_message_bytes, chunks);
  auto roudi = std::make_unique<shm::RoudiProcess>(out_dir + "/roudi", plan);
  try {
    roudi->Start();
  } catch (const std::exception& e) {
    event_(std::string("shared memory unavailable: ") + e.what() +
           (iox ? "\nthe stages use LCM multicast on this host (" + coordinator_url_ + ")"
                : std::string("\nthe stages use DDS's network path (shm=0)")));
    stage_url_ = coordinator_url_;
    needs_bridge_ = false;
    return;
  }
  roudi_ = std::move(roudi);
  if (UrlParameter(url, max_key).empty())
    stage_url_ = WithUrlParameter(url, max_key, std::to_string(shm::LargestShmMessage(plan)));
  event_("shared memory: started iox-roudi (pid " + std::to_string(roudi_->pid()) + ", " +
         std::to_string(plan.total_bytes() >> 20) + " MiB of pools, config " + roudi_->config_path() + "); stages on " +
         stage_url_);
}

SharedMemoryTransport::~SharedMemoryTransport() { Stop(); }

bool SharedMemoryTransport::RestartIfDead() {
  if (!roudi_ || roudi_->Alive()) return false;
  event_("shared memory: iox-roudi exited (the stages attached to it are ended with it); starting it again");
  try {
    roudi_->Start();
  } catch (const std::exception& e) {
    event_(std::string("shared memory: RouDi does not start again: ") + e.what() +
           (needs_bridge_ ? "\nthe stages use LCM multicast on this host (" + coordinator_url_ + ") from now on"
                          : std::string("\nthe stages use DDS's network path from now on")));
    roudi_.reset();
    stage_url_ = coordinator_url_;
  }
  return true;
}

void SharedMemoryTransport::Stop() {
  if (roudi_) roudi_->Stop();
}

}  // namespace fusecal
