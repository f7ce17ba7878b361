#include "runtime/shared_memory.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/statvfs.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "runtime/child_process.hpp"

namespace fusecal::shm {

namespace {

constexpr size_t kMiB = 1u << 20;

std::string Megabytes(size_t bytes) {
  std::ostringstream text;
  text.precision(0);
  text << std::fixed << double(bytes) / double(kMiB) << " MiB";
  return text.str();
}

std::string FileTail(const std::string& path, size_t max_bytes) {
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return text.size() > max_bytes ? text.substr(text.size() - max_bytes) : text;
}

}  // namespace

size_t PoolPlan::largest_chunk() const {
  size_t largest = 0;
  for (const auto& pool : pools) largest = std::max(largest, pool.chunk_bytes);
  return largest;
}

size_t PoolPlan::total_bytes() const {
  size_t total = 0;
  for (const auto& pool : pools) total += pool.chunk_bytes * static_cast<size_t>(pool.count);
  return total;
}

PoolPlan PlanPools(size_t max_message_bytes, int bulk_chunks) {
  // iceoryx wants chunk sizes that are multiples of 32 bytes; whole MiB keep the TOML readable.
  const size_t bulk_chunk = (max_message_bytes + kChunkOverheadBytes + kMiB - 1) / kMiB * kMiB;
  PoolPlan plan;
  plan.pools.push_back({16 * 1024, 1024});  // STATUS, motions, EXTRINSIC, camera info
  plan.pools.push_back({256 * 1024, 64});   // motion sets, small images
  if (bulk_chunk > 2 * kMiB) plan.pools.push_back({2 * kMiB, std::max(bulk_chunks / 2, 4)});  // scans
  plan.pools.push_back({bulk_chunk, std::max(bulk_chunks, 1)});                               // images, scans, stations
  return plan;
}

std::string RoudiConfigToml(const PoolPlan& plan) {
  std::ostringstream toml;
  toml << "# Written by fusecal for iox-roudi: pools sized for the pipeline's largest message.\n"
       << "[general]\nversion = 1\n\n[[segment]]\n";
  for (const auto& pool : plan.pools)
    toml << "\n[[segment.mempool]]\nsize = " << pool.chunk_bytes << "\ncount = " << pool.count << "\n";
  return toml.str();
}

size_t LargestShmMessage(const PoolPlan& plan) {
  const size_t largest = plan.largest_chunk();
  return largest > kChunkOverheadBytes ? largest - kChunkOverheadBytes : 0;
}

ShmSpace QueryShmSpace(const std::string& dir) {
  ShmSpace space;
  struct statvfs st {};
  if (statvfs(dir.c_str(), &st) != 0) return space;
  space.exists = true;
  space.total_bytes = static_cast<size_t>(st.f_blocks) * st.f_frsize;
  space.free_bytes = static_cast<size_t>(st.f_bavail) * st.f_frsize;
  return space;
}

std::string CheckPlanFits(const PoolPlan& plan, const ShmSpace& space, const std::string& dir) {
  const size_t needed = plan.total_bytes() + kRoudiManagementBytes;
  // Whole GiB with room to spare for the remount advice.
  const size_t advise_gib = (needed + (1u << 30) - 1) / (1u << 30) + 1;
  if (!space.exists)
    return dir + " does not exist: the shared-memory transport needs it (mount -t tmpfs -o size=" +
           std::to_string(advise_gib) + "g tmpfs " + dir + "), or use dds://?shm=0";
  if (space.free_bytes >= needed) return {};
  return dir + " has " + Megabytes(space.free_bytes) + " free of " + Megabytes(space.total_bytes) +
         " but RouDi's pools need " + Megabytes(needed) + " (" + std::to_string(plan.pools.back().count) +
         " chunks of " + Megabytes(plan.largest_chunk()) +
         " and smaller ones): RouDi would die with SIGBUS. Fix: mount -o remount,size=" + std::to_string(advise_gib) +
         "g " + dir + " (docker: --shm-size=" + std::to_string(advise_gib) + "g), or use the network path (shm=0)";
}

bool RoudiRunning() {
  // iceoryx 2.x: RouDi listens on the unix datagram socket /tmp/roudi (IPC_CHANNEL_ROUDI_NAME).
  const int fd = socket(AF_UNIX, SOCK_DGRAM, 0);
  if (fd < 0) return false;
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::strncpy(address.sun_path, "/tmp/roudi", sizeof(address.sun_path) - 1);
  const bool running = connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) == 0;
  close(fd);
  return running;
}

namespace {

// RouDi holds an exclusive flock on this file from its start until its process has ended, which is
// later than its socket closes: a new RouDi started in between aborts (ROUDI_STILL_RUNNING). Probing
// takes the lock for an instant, so it is used only while waiting for a RouDi to go, never while one
// is starting.
bool RoudiLockHeld() {
  const int fd = open("/tmp/iox-unique-roudi.lock", O_RDONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool held = flock(fd, LOCK_EX | LOCK_NB) != 0 && errno == EWOULDBLOCK;
  close(fd);  // releases the lock if the probe got it
  return held;
}

}  // namespace

std::string RoudiExecutable() {
  for (const char* candidate : {"/usr/bin/iox-roudi", "/usr/local/bin/iox-roudi"})
    if (access(candidate, X_OK) == 0) return candidate;
  return {};
}

RoudiProcess::RoudiProcess(std::string work_dir, PoolPlan plan)
    : work_dir_(std::move(work_dir)), plan_(std::move(plan)) {}

RoudiProcess::~RoudiProcess() { Stop(); }

void RoudiProcess::Start(double timeout_s) {
  exe_ = RoudiExecutable();
  if (exe_.empty())
    throw std::runtime_error("iox-roudi is not installed (Debian package iceoryx: tools/setup installs it)");
  if (const std::string problem = CheckPlanFits(plan_, QueryShmSpace()); !problem.empty())
    throw std::runtime_error(problem);
  if (!WaitUntilRoudiGone(3))  // (one told to stop just now takes a moment to end)
    throw std::runtime_error(
        "a RouDi that fusecal did not start is already running (socket /tmp/roudi); "
        "stop it, or run without shm=1");
  std::filesystem::create_directories(work_dir_);
  {
    std::ofstream config(config_path());
    config << RoudiConfigToml(plan_);
    config.close();  // a full /tmp shows only at the flush
    if (!config) throw std::runtime_error("cannot write " + config_path());
  }
  // A RouDi that ended a moment ago can still hold its lock when the new one looks (measured once in a
  // run whose RouDi was SIGKILLed): the new one then aborts with ROUDI_STILL_RUNNING, and is retried.
  for (int attempt = 1;; ++attempt) {
    if (Launch(timeout_s)) {
      ++starts_;
      return;
    }
    const std::string tail = FileTail(log_path(), 1500);
    if (attempt < 3 && tail.find("ROUDI_STILL_RUNNING") != std::string::npos && WaitUntilRoudiGone(3)) continue;
    throw std::runtime_error("iox-roudi exited at start (config " + config_path() + "); end of " + log_path() + ":\n" +
                             tail);
  }
}

bool RoudiProcess::Launch(double timeout_s) {
  const std::string log = log_path();
  const std::string config = config_path();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed for iox-roudi");
  if (pid == 0) {
    setpgid(0, 0);                     // Ctrl-C reaches the stages, not RouDi: it is stopped after them
    prctl(PR_SET_PDEATHSIG, SIGTERM);  // and it does not outlive whoever started it
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (fd >= 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
    }
    // -k 2: processes still attached when RouDi stops get SIGKILL 2 s after SIGTERM. -l error: at
    // warning level RouDi notes every reader whose history request exceeds the writer's (harmless).
    execl(exe_.c_str(), exe_.c_str(), "-c", config.c_str(), "-k", "2", "-l", "error", static_cast<char*>(nullptr));
    _exit(127);
  }
  pid_ = pid;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!RoudiRunning()) {
    if (!Alive()) return false;
    if (std::chrono::steady_clock::now() > deadline) {
      Stop(1);
      throw std::runtime_error("iox-roudi did not answer within " + std::to_string(int(timeout_s)) + " s; end of " +
                               log + ":\n" + FileTail(log, 1500));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

bool RoudiProcess::Alive() {
  if (pid_ <= 0) return false;
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) == pid_) {
    pid_ = -1;
    return false;
  }
  return true;
}

void RoudiProcess::LeaveUntilExit() { pid_ = -1; }

bool WaitUntilRoudiGone(double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (RoudiRunning() || RoudiLockHeld()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

void RoudiProcess::Stop(double grace_s) {
  if (pid_ <= 0) return;
  kill(pid_, SIGTERM);
  ReapOrKill(pid_, grace_s);
  pid_ = -1;
}

}  // namespace fusecal::shm
