#include "tools/bench/transport/probe_runner.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <thread>
#include <vector>

namespace fusecal::bench {

namespace {

using Clock = std::chrono::steady_clock;

// After the last send, how long the subscriber may take for stragglers.
constexpr double kDrainS = 2.0;
// How long a child may take to write its result and exit once told to stop.
constexpr double kExitGraceS = 10.0;

std::atomic<bool> g_interrupted{false};

double SecondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// A child process running this executable in one role; its stderr goes to `log_path`.
class Child {
 public:
  Child(const std::string& executable, const std::vector<std::string>& args, const std::string& log_path) {
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(executable.c_str()));
    for (const auto& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
    argv.push_back(nullptr);
    pid_ = fork();
    if (pid_ == 0) {
      const int log = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (log >= 0) {
        dup2(log, STDOUT_FILENO);
        dup2(log, STDERR_FILENO);
      }
      execv(executable.c_str(), argv.data());
      _exit(127);
    }
  }
  ~Child() { Kill(); }

  // False once the process has exited (reaped here).
  bool Running() {
    if (pid_ <= 0) return false;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) != pid_) return true;
    exit_status_ = status;
    pid_ = -1;
    return false;
  }
  // Waits up to `timeout_s` for the process to exit by itself; then SIGKILL. True when it exited alone.
  bool WaitExit(double timeout_s) {
    const auto start = Clock::now();
    while (Running()) {
      if (SecondsSince(start) > timeout_s) {
        Kill();
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return true;
  }
  void Kill() {
    if (pid_ <= 0) return;
    kill(pid_, SIGKILL);
    waitpid(pid_, &exit_status_, 0);
    pid_ = -1;
  }
  std::string ExitDescription() const {
    if (WIFEXITED(exit_status_)) return "exit status " + std::to_string(WEXITSTATUS(exit_status_));
    if (WIFSIGNALED(exit_status_)) return "killed by signal " + std::to_string(WTERMSIG(exit_status_));
    return "still running";
  }

 private:
  pid_t pid_ = -1;
  int exit_status_ = -2;
};

std::vector<std::string> RoleArgs(const std::string& role, const ProbeConfig& c) {
  return {"--role",       role,
          "--url",        c.url,
          "--channel",    c.channel,
          "--size",       std::to_string(c.size_bytes),
          "--rate",       std::to_string(c.rate_hz),
          "--count",      std::to_string(c.count),
          "--subscriber", c.busy ? "busy" : "idle",
          "--tag",        std::to_string(c.run_tag),
          "--dir",        c.dir,
          "--timeout",    std::to_string(c.timeout_s)};
}

// The last lines of a child's stderr (transport warnings), each prefixed with `who`.
std::string LogTail(const std::string& path, const std::string& who, size_t max_lines = 6) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(line);
  std::string text;
  for (size_t i = lines.size() > max_lines ? lines.size() - max_lines : 0; i < lines.size(); ++i)
    text += "    " + who + ": " + lines[i] + "\n";
  return text;
}

void AddNote(std::string& note, const std::string& text) {
  if (text.empty()) return;
  if (!note.empty()) note += "; ";
  note += text;
}

}  // namespace

void RequestInterrupt() { g_interrupted = true; }
bool Interrupted() { return g_interrupted; }

Measurement RunConfiguration(const std::string& executable, const ProbeConfig& config) {
  const ProbeFiles files{config.dir};
  Measurement m;
  Child subscriber(executable, RoleArgs("subscriber", config), config.dir + "/subscriber.log");
  Child publisher(executable, RoleArgs("publisher", config), config.dir + "/publisher.log");

  // Send phase: until the publisher says it is done (or fails, or the run is interrupted).
  const auto start = Clock::now();
  bool timed_out = false;
  while (!FileExists(files.sent()) && publisher.Running() && subscriber.Running() && !Interrupted()) {
    if (SecondsSince(start) > config.timeout_s + 5) {
      timed_out = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  // Drain: the subscriber stops by itself once it has every message.
  const auto drain_start = Clock::now();
  while (subscriber.Running() && SecondsSince(drain_start) < kDrainS && !Interrupted())
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  TouchFile(files.stop());
  const bool subscriber_exited = subscriber.WaitExit(kExitGraceS);
  const bool publisher_exited = publisher.WaitExit(kExitGraceS);

  const SubscriberResult sub = ReadSubscriberResult(files.subscriber_result());
  const PublisherResult pub = ReadPublisherResult(files.publisher_result());
  m.sent = pub.sent;
  m.delivered = sub.delivered;
  m.mean_ms = sub.mean_ms;
  m.p99_ms = sub.p99_ms;
  m.shared_memory = sub.shared_memory && pub.shared_memory;
  if (pub.sent > 0 && pub.send_end_utime > pub.send_start_utime) {
    // The window: from the first send to the later of the last send and the last delivery. Both
    // processes' CPU over that same window (work on lost messages after it is not counted).
    const int64_t end = std::max(pub.send_end_utime, sub.last_receive_utime);
    const double wall_s = 1e-6 * static_cast<double>(end - pub.send_start_utime);
    const double cpu_s =
        CpuBetween(pub.cpu, pub.send_start_utime, end) + CpuBetween(sub.cpu, pub.send_start_utime, end);
    m.cpu_pct = 100.0 * cpu_s / wall_s;
  }

  if (Interrupted()) AddNote(m.note, "interrupted");
  if (timed_out) AddNote(m.note, "timed out after " + std::to_string(int(config.timeout_s + 5)) + " s");
  if (!pub.found)
    AddNote(m.note, "publisher wrote no result (" + publisher.ExitDescription() + ")");
  else if (!pub.error.empty())
    AddNote(m.note, "publisher: " + pub.error);
  if (!sub.found)
    AddNote(m.note, "subscriber wrote no result (" + subscriber.ExitDescription() + ")");
  else if (!sub.error.empty())
    AddNote(m.note, "subscriber: " + sub.error);
  if (sub.bus_dropped > 0)
    AddNote(m.note, "the subscriber's bus counted " + std::to_string(sub.bus_dropped) + " lost (dropped_messages)");
  if (!subscriber_exited) AddNote(m.note, "subscriber did not stop, killed");
  if (!publisher_exited) AddNote(m.note, "publisher did not stop, killed");
  if (pub.found && pub.error.empty() && !pub.warmed) AddNote(m.note, "warm-up not confirmed within 10 s (sent anyway)");
  m.child_output =
      LogTail(config.dir + "/subscriber.log", "subscriber") + LogTail(config.dir + "/publisher.log", "publisher");
  return m;
}

}  // namespace fusecal::bench
