#include <cstdlib>

#include "runtime/bus.hpp"
#include "runtime/bus_url.hpp"
#include "runtime/lcm_bus.hpp"
#ifdef FUSECAL_WITH_DDS
#include "runtime/dds/dds_bus.hpp"
#endif
#ifdef FUSECAL_WITH_IOX
#include "runtime/iox/iox_bus.hpp"
#endif

namespace fusecal {

std::string DefaultBusUrl() {
  if (const char* env = std::getenv("LCM_DEFAULT_URL"); env && *env) return env;
  return "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=67108864";
}

bool SharedMemoryBusBuilt() {
#ifdef FUSECAL_WITH_IOX
  return true;
#else
  return false;
#endif
}

std::unique_ptr<Bus> MakeBus(const std::string& url) {
  const std::string chosen = url.empty() ? DefaultBusUrl() : url;
  const std::string scheme = ParseBusUrl(chosen).scheme;  // every option checked, for every transport
  if (scheme == "udpm" || scheme == "memq" || scheme == "file" || scheme == "tcpq")
    return std::make_unique<LcmBus>(chosen);
  if (scheme == "dds") {
#ifdef FUSECAL_WITH_DDS
    return std::make_unique<DdsBus>(chosen);
#else
    throw BusError("bus URL '" + chosen +
                   "': this fusecal was built without DDS (install cyclonedds-dev and cyclonedds-tools, "
                   "then reconfigure with -DFUSECAL_WITH_DDS=ON)");
#endif
  }
  if (scheme == "iox") {
#ifdef FUSECAL_WITH_IOX
    return std::make_unique<IoxBus>(chosen);
#else
    throw BusError("bus URL '" + chosen +
                   "': this fusecal was built without iceoryx (install libiceoryx-binding-c-dev and iceoryx, "
                   "then reconfigure with -DFUSECAL_WITH_IOX=ON)");
#endif
  }
  throw BusError("bus URL '" + chosen + "': unknown transport '" + scheme + "' (expected one of " + BusUrlSchemes() +
                 ")");
}

}  // namespace fusecal
