#include "runtime/iox/iox_runtime.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <fstream>
#include <mutex>

#include "runtime/iox/iceoryx_c.hpp"
#include "runtime/bus.hpp"
#include "runtime/shared_memory.hpp"

namespace fusecal::iox {

namespace {

// RouDi's unix socket (iceoryx 2.x). A new RouDi creates it anew: its inode tells RouDis apart.
constexpr const char* kRoudiSocket = "/tmp/roudi";

std::mutex g_mutex;
bool g_registered = false;
ino_t g_roudi_inode = 0;

ino_t RoudiInode() {
  struct stat info {};
  return stat(kRoudiSocket, &info) == 0 ? info.st_ino : 0;
}

// "fusecal_<pid>_<program>": unique among the processes attached to one RouDi, and readable in its log.
std::string RuntimeName() {
  std::string program;
  std::ifstream("/proc/self/comm") >> program;
  std::string name = "fusecal_" + std::to_string(getpid()) + (program.empty() ? "" : "_" + program);
  std::string safe;
  for (char c : name) safe += (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-') ? c : '_';
  return safe.substr(0, 90);
}

}  // namespace

void EnsureRuntime(const std::string& what) {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (!shm::RoudiRunning())
    throw BusError(what + ": no iceoryx RouDi is running (start iox-roudi, or use `fusecal run`, which starts one)");
  if (g_registered) {
    if (RoudiInode() != g_roudi_inode)
      throw BusError(what + ": the RouDi this process registered with has been replaced by a new one; iceoryx "
                            "cannot move a process to another RouDi: restart the process");
    return;
  }
  g_roudi_inode = RoudiInode();
  // iceoryx logs every registration and cleanup at Debug/Verbose on stderr (the stage logs); warnings
  // and errors are enough.
  iox_set_loglevel(Iceoryx_LogLevel_Warn);
  iox_runtime_init(RuntimeName().c_str());
  g_registered = true;
}

}  // namespace fusecal::iox
