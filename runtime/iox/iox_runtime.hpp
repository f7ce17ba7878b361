// This process's registration with iceoryx's RouDi, shared by every IoxBus (and the raw-iceoryx probe of
// tools/bench-transport). iceoryx registers a process once (iox_runtime_init) and cannot move it to another
// RouDi, so the checks here turn what iceoryx would do in those cases (wait for RouDi, then abort; or talk
// to a RouDi that does not know the process) into a BusError.
#pragma once

#include <cstddef>
#include <string>

namespace fusecal::iox {

// Registers this process with the running RouDi on the first call (name "fusecal_<pid>_<program>").
// Throws BusError, without calling iceoryx, when no RouDi answers, or when the RouDi that answers is not
// the one this process registered with (it was restarted: the process must be restarted too). `what`
// names the caller in the message (a bus URL).
void EnsureRuntime(const std::string& what);

// The largest payload a chunk of the RouDi this process registered with holds (its mempools' largest
// `size`), or 0 when unknown. iceoryx aborts a process that loans a chunk larger than every pool; the bus
// refuses such a message with a BusError instead. Read once, at registration, from the config file of the
// running iox-roudi (its `-c FILE`, found through /proc); without `-c` RouDi's built-in pools stop at 4 MiB.
size_t LargestChunkPayload();

// The same for a given iox-roudi command line and TOML text (for tests): 0 when the config has no pool.
size_t LargestPayloadOfConfig(const std::string& toml);

}  // namespace fusecal::iox
