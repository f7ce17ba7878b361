#include "runtime/iox/iox_runtime.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <vector>

#include "runtime/bus.hpp"
#include "runtime/iox/iceoryx_c.hpp"
#include "runtime/shared_memory.hpp"

namespace fusecal::iox {

namespace {

// RouDi's unix socket (iceoryx 2.x). A new RouDi creates it anew: its inode tells RouDis apart.
constexpr const char* kRoudiSocket = "/tmp/roudi";

std::mutex g_mutex;
bool g_registered = false;
ino_t g_roudi_inode = 0;
size_t g_largest_payload = 0;

constexpr size_t kBuiltInLargestPayload = 4u << 20;  // iceoryx 2.0's default mempools

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

// The arguments of the running iox-roudi (empty when none is found or /proc cannot be read), and its
// working directory (for a relative config path).
std::vector<std::string> RoudiCommandLine(std::string* cwd) {
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator("/proc", error)) {
    const std::string pid = entry.path().filename().string();
    if (pid.empty() || !std::isdigit(static_cast<unsigned char>(pid[0]))) continue;
    std::string comm = ReadFile(entry.path().string() + "/comm");
    if (comm.rfind("iox-roudi", 0) != 0) continue;
    const std::string cmdline = ReadFile(entry.path().string() + "/cmdline");
    if (cmdline.empty()) continue;  // a zombie
    std::vector<std::string> args;
    for (size_t start = 0; start < cmdline.size();) {
      const size_t end = cmdline.find('\0', start);
      args.push_back(cmdline.substr(start, end == std::string::npos ? std::string::npos : end - start));
      if (end == std::string::npos) break;
      start = end + 1;
    }
    *cwd = std::filesystem::read_symlink(entry.path() / "cwd", error).string();
    return args;
  }
  return {};
}

size_t ReadLargestPayload() {
  std::string cwd;
  const std::vector<std::string> args = RoudiCommandLine(&cwd);
  if (args.empty()) return 0;
  std::string config;
  for (size_t i = 1; i < args.size(); ++i) {
    if ((args[i] == "-c" || args[i] == "--config-file") && i + 1 < args.size()) config = args[i + 1];
    if (args[i].rfind("--config-file=", 0) == 0) config = args[i].substr(14);
  }
  if (config.empty()) return kBuiltInLargestPayload;
  if (config[0] != '/' && !cwd.empty()) config = cwd + "/" + config;
  const std::string toml = ReadFile(config);
  return toml.empty() ? 0 : LargestPayloadOfConfig(toml);
}

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

size_t LargestPayloadOfConfig(const std::string& toml) {
  // Every `size = N` line of a [[segment.mempool]] table (the only `size` key of RouDi's config).
  size_t largest = 0;
  std::istringstream lines(toml);
  for (std::string line; std::getline(lines, line);) {
    const auto key = line.find_first_not_of(" \t");
    if (key == std::string::npos || line.compare(key, 4, "size") != 0) continue;
    const auto eq = line.find('=', key + 4);
    if (eq == std::string::npos || line.find_first_not_of(" \t", key + 4) != eq) continue;
    try {
      largest = std::max(largest, static_cast<size_t>(std::stoull(line.substr(eq + 1))));
    } catch (const std::exception&) {
    }
  }
  return largest;
}

size_t LargestChunkPayload() {
  std::lock_guard<std::mutex> lock(g_mutex);
  return g_largest_payload;
}

void EnsureRuntime(const std::string& what) {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (!shm::RoudiRunning())
    throw BusError(what + ": no iceoryx RouDi is running (start iox-roudi, or use `fusecal run`, which starts one)");
  if (g_registered) {
    if (RoudiInode() != g_roudi_inode)
      throw BusError(what +
                     ": the RouDi this process registered with has been replaced by a new one; iceoryx "
                     "cannot move a process to another RouDi: restart the process");
    return;
  }
  g_roudi_inode = RoudiInode();
  g_largest_payload = ReadLargestPayload();
  // iceoryx logs every registration and cleanup at Debug/Verbose on stderr (the stage logs); warnings
  // and errors are enough.
  iox_set_loglevel(Iceoryx_LogLevel_Warn);
  iox_runtime_init(RuntimeName().c_str());
  g_registered = true;
}

}  // namespace fusecal::iox
