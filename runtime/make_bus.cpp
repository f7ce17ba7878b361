#include <cstdlib>

#include "runtime/bus.hpp"
#include "runtime/lcm_bus.hpp"

namespace fusecal {

std::string DefaultBusUrl() {
  if (const char* env = std::getenv("LCM_DEFAULT_URL"); env && *env) return env;
  return "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=67108864";
}

std::unique_ptr<Bus> MakeBus(const std::string& url) {
  const std::string chosen = url.empty() ? DefaultBusUrl() : url;
  const auto scheme_end = chosen.find("://");
  if (scheme_end == std::string::npos)
    throw BusError("bus URL '" + chosen + "' has no scheme (expected udpm://, memq:// or file://)");
  const std::string scheme = chosen.substr(0, scheme_end);
  if (scheme == "udpm" || scheme == "memq" || scheme == "file" || scheme == "tcpq")
    return std::make_unique<LcmBus>(chosen);
  throw BusError("bus URL '" + chosen + "': unknown transport '" + scheme +
                 "' (expected udpm, memq, file or tcpq)");
}

}  // namespace fusecal
