// iceoryx shared memory for the DDS bus (dds://?shm=1): RouDi's memory pools sized for the pipeline's
// messages, the /dev/shm check that comes before them, and a RouDi process that fusecal starts, watches
// and stops. Nothing here needs DDS; the bus only asks RoudiRunning() before enabling shared memory.
//
// Measured with Cyclone DDS 0.10.2 + iceoryx 2.0.3 (Debian), and why this module exists:
// - RouDi's built-in pools stop at 4 MiB chunks; a larger sample aborts the publishing process
//   ("Could not find a fitting mempool"). The pools here are planned from the largest message.
// - With a 64 MB /dev/shm (a container default) RouDi dies with SIGBUS: the space is checked first.
// - A participant with shared memory and no RouDi waits 60 s and aborts: RoudiRunning() comes first.
// - Stopping RouDi terminates every process attached to it (SIGTERM, then SIGKILL after the kill
//   delay), and a process cannot re-attach to a new RouDi: whoever supervises restarts them.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <string>
#include <vector>

namespace fusecal::shm {

struct MemPool {
  size_t chunk_bytes = 0;
  int count = 0;
};

// The segment RouDi creates: its pools, smallest chunks first.
struct PoolPlan {
  std::vector<MemPool> pools;
  size_t largest_chunk() const;
  size_t total_bytes() const;  // chunks only; RouDi's management segment comes on top
};

// Bytes a chunk needs beyond the payload: iceoryx's chunk header and Cyclone's sample header (channel
// name, utime, sequence length). Messages bigger than a chunk minus this go over the network path.
inline constexpr size_t kChunkOverheadBytes = 4096;

// The pipeline's defaults (configs/pipeline.yaml, bus.max_message_bytes and bus.shm_chunks): a station
// of a 2048x1024 RGB panorama and a 128k-point scan is ~8.5 MB.
inline constexpr size_t kDefaultMaxMessageBytes = 12u << 20;
inline constexpr int kDefaultBulkChunks = 32;

// Pools for messages up to `max_message_bytes`: `bulk_chunks` chunks that each hold the largest message
// (images, scans, stations), plus medium and small pools for everything else.
PoolPlan PlanPools(size_t max_message_bytes, int bulk_chunks);

// RouDi's TOML configuration (iceoryx 2.x format) for the plan.
std::string RoudiConfigToml(const PoolPlan& plan);

// The largest message the plan carries in shared memory (the bus's shm_max=).
size_t LargestShmMessage(const PoolPlan& plan);

struct ShmSpace {
  bool exists = false;
  size_t total_bytes = 0;
  size_t free_bytes = 0;
};
ShmSpace QueryShmSpace(const std::string& dir = "/dev/shm");

// Room RouDi needs besides the chunks (management segment, introspection), measured ~50 MB; rounded up.
inline constexpr size_t kRoudiManagementBytes = 128u << 20;

// Empty when the plan fits in `space`; otherwise a message that says what is missing and how to fix it.
std::string CheckPlanFits(const PoolPlan& plan, const ShmSpace& space, const std::string& dir = "/dev/shm");

// Whether an iceoryx RouDi answers on this machine (its unix socket /tmp/roudi accepts a connection;
// a stale socket file left by a dead RouDi does not).
bool RoudiRunning();

// Waits until no RouDi answers and its process has ended (one that was told to stop takes a moment, and
// a new one started before it has ended aborts); false after `timeout_s`.
bool WaitUntilRoudiGone(double timeout_s = 5);

// The iox-roudi executable (Debian package iceoryx), or empty when it is not installed.
std::string RoudiExecutable();

// A RouDi started by fusecal: config and log in `work_dir` (roudi_config.toml, roudi.log).
class RoudiProcess {
 public:
  RoudiProcess(std::string work_dir, PoolPlan plan);
  ~RoudiProcess();
  RoudiProcess(const RoudiProcess&) = delete;
  RoudiProcess& operator=(const RoudiProcess&) = delete;

  // Checks /dev/shm, writes the config, starts iox-roudi and waits until it answers. Throws
  // std::runtime_error with a clear message (and the end of roudi.log) when it cannot: no iox-roudi,
  // /dev/shm too small, another RouDi already running, RouDi exiting or not answering in time.
  void Start(double timeout_s = 15);
  // False once the process has exited (or was never started); reaps it.
  bool Alive();
  // SIGTERM (RouDi then ends the processes still attached to it), SIGKILL after `grace_s`.
  void Stop(double grace_s = 5);
  // For a process that is itself attached to RouDi (Stop() would end it too): RouDi is left running
  // and gets SIGTERM when this process exits (it is started with PR_SET_PDEATHSIG).
  void LeaveUntilExit();

  pid_t pid() const { return pid_; }
  const PoolPlan& plan() const { return plan_; }
  std::string config_path() const { return work_dir_ + "/roudi_config.toml"; }
  std::string log_path() const { return work_dir_ + "/roudi.log"; }
  int starts() const { return starts_; }

 private:
  // Starts iox-roudi once; false when it exited before answering.
  bool Launch(double timeout_s);

  std::string work_dir_;
  std::string exe_;
  PoolPlan plan_;
  pid_t pid_ = -1;
  int starts_ = 0;
};

}  // namespace fusecal::shm
