// Starts the stage executables as separate processes and keeps them running: a stage that dies
// (crash, SIGKILL) is started again; Stop() ends them all with SIGTERM (SIGKILL after a grace period).
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace fusecal {

struct StageProcess {
  std::string name;        // e.g. "lidar_icp"
  std::string executable;  // full path of fusecal-<name>
  std::vector<std::string> args;
  pid_t pid = -1;
  int restarts = 0;
};

class Supervisor {
 public:
  explicit Supervisor(std::string log_dir) : log_dir_(std::move(log_dir)) {}
  ~Supervisor() { Stop(); }

  // Throws std::runtime_error when an executable is missing.
  void Add(StageProcess process);
  void StartAll();
  // Restarts stages that have exited; returns a line for each restart.
  std::vector<std::string> Poll();
  // Ends every stage (SIGKILL) and starts it again, e.g. after the RouDi they were attached to died.
  void RestartAll();
  // Replaces an argument of every stage from its next start on (e.g. the bus URL).
  void ReplaceArgument(const std::string& from, const std::string& to);
  void Stop();
  const std::vector<StageProcess>& processes() const { return processes_; }

 private:
  void Launch(StageProcess& p);
  static void Reap(StageProcess& p, double grace_s);
  std::string log_dir_;
  std::vector<StageProcess> processes_;
};

// Directory of the running executable (where the stage executables are installed beside it).
std::string ExecutableDir();

}  // namespace fusecal
