// `fusecal doctor`: checks what the bus needs on this machine and says how to fix each problem.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace fusecal {

struct DoctorFinding {
  std::string check;  // e.g. "receive buffer"
  bool ok = true;
  bool loses_messages = false;  // a problem that would drop messages (exit status 1)
  std::string detail;           // what was found
  std::string fix;              // the exact command that fixes it (empty when ok)
};

// Runs every check for the given bus URL (empty: the default URL). With `apply_fixes`, runs the fix
// commands first (needs root) and then checks again. `ros2_receive_buffer` > 0 also checks that the
// kernel lets fusecal-ros2-input have a socket receive buffer of that many bytes (`--ros2`).
std::vector<DoctorFinding> RunDoctor(const std::string& bus_url, bool apply_fixes, size_t ros2_receive_buffer = 0);

}  // namespace fusecal
