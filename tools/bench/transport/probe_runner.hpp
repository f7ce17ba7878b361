// Runs one benchmark configuration: starts the subscriber and the publisher as child processes (this
// executable with `--role ...`), waits for the send phase and a drain of up to 2 s, stops both, and
// combines their result files into one measurement.
#pragma once

#include <string>

#include "tools/bench/transport/transport_probe.hpp"

namespace fusecal::bench {

struct Measurement {
  int sent = 0;
  int delivered = 0;
  double mean_ms = 0, p99_ms = 0;  // meaningful when delivered > 0
  // (publisher CPU + subscriber CPU) / wall time, in percent, over the send phase and its drain: from
  // the first send to the later of the last send and the last delivery. Summed over both processes, so
  // it can exceed 100 on a multi-core machine. Negative when nothing was sent.
  double cpu_pct = -1;
  bool shared_memory = false;  // both ends used iceoryx (dds-shm)
  std::string note;            // why something is missing: errors of either process, timeouts
  std::string child_output;    // the end of what the two processes wrote on stderr, indented
};

// `executable`: this program (for the child processes). `config.dir` must exist and be empty.
Measurement RunConfiguration(const std::string& executable, const ProbeConfig& config);

// Set from a SIGINT/SIGTERM handler: the running configuration stops its children and returns.
void RequestInterrupt();
bool Interrupted();

}  // namespace fusecal::bench
