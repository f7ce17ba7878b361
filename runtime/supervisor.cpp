#include "runtime/supervisor.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <stdexcept>

#include "runtime/child_process.hpp"

namespace fusecal {

std::string ExecutableDir() {
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? "." : self.parent_path().string();
}

void Supervisor::Add(StageProcess process) {
  if (access(process.executable.c_str(), X_OK) != 0)
    throw std::runtime_error("stage executable not found: " + process.executable + " (build it: tools/setup)");
  processes_.push_back(std::move(process));
}

void Supervisor::Launch(StageProcess& p) {
  const std::string log = log_dir_ + "/" + p.name + ".log";
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed for stage " + p.name);
  if (pid == 0) {
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (fd >= 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
    }
    std::vector<char*> argv{const_cast<char*>(p.executable.c_str())};
    for (auto& a : p.args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(p.executable.c_str(), argv.data());
    _exit(127);
  }
  p.pid = pid;
}

void Supervisor::StartAll() {
  for (auto& p : processes_) Launch(p);
}

std::vector<std::string> Supervisor::Poll() {
  std::vector<std::string> events;
  for (auto& p : processes_) {
    if (p.pid <= 0) continue;
    int status = 0;
    if (waitpid(p.pid, &status, WNOHANG) != p.pid) continue;
    const std::string how = WIFSIGNALED(status) ? "killed by signal " + std::to_string(WTERMSIG(status))
                                                : "exited with status " + std::to_string(WEXITSTATUS(status));
    ++p.restarts;
    Launch(p);
    events.push_back("stage " + p.name + " " + how + "; restarted (restart " + std::to_string(p.restarts) + ")");
  }
  return events;
}

void Supervisor::RestartAll() {
  for (auto& p : processes_) {
    if (p.pid > 0) {
      kill(p.pid, SIGKILL);
      Reap(p, 5);
    }
    ++p.restarts;
    Launch(p);
  }
}

void Supervisor::ReplaceArgument(const std::string& from, const std::string& to) {
  for (auto& p : processes_) std::replace(p.args.begin(), p.args.end(), from, to);
}

// Waits for a signalled stage to exit; SIGKILL once `grace_s` has passed.
void Supervisor::Reap(StageProcess& p, double grace_s) {
  ReapOrKill(p.pid, grace_s);
  p.pid = -1;
}

void Supervisor::Stop() {
  for (auto& p : processes_)
    if (p.pid > 0) kill(p.pid, SIGTERM);
  const auto start = std::chrono::steady_clock::now();
  for (auto& p : processes_) {
    const double spent = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    Reap(p, std::max(0.0, 5.0 - spent));
  }
}

}  // namespace fusecal
