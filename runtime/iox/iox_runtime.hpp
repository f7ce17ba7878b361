// This process's registration with iceoryx's RouDi, shared by every IoxBus (and the raw-iceoryx probe of
// tools/bench-transport). iceoryx registers a process once (iox_runtime_init) and cannot move it to another
// RouDi, so the checks here turn what iceoryx would do in those cases (wait for RouDi, then abort; or talk
// to a RouDi that does not know the process) into a BusError.
#pragma once

#include <string>

namespace fusecal::iox {

// Registers this process with the running RouDi on the first call (name "fusecal_<pid>_<program>").
// Throws BusError, without calling iceoryx, when no RouDi answers, or when the RouDi that answers is not
// the one this process registered with (it was restarted: the process must be restarted too). `what`
// names the caller in the message (a bus URL).
void EnsureRuntime(const std::string& what);

}  // namespace fusecal::iox
