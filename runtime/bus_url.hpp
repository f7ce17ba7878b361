// Reading and changing the query parameters of a bus URL (udpm://...?ttl=0, dds://?domain=0&shm=1).
#pragma once

#include <stdexcept>
#include <string>

#include "runtime/bus_error.hpp"

namespace fusecal {

// The value of `key=` in the query of a URL, or empty.
std::string UrlParameter(const std::string& url, const std::string& key);

// The URL with `key=value` in its query: replaced where present, appended otherwise.
std::string WithUrlParameter(const std::string& url, const std::string& key, const std::string& value);

// A dds:// URL asking for shared memory (shm=1).
bool IsSharedMemoryDdsUrl(const std::string& url);

// An iox:// URL (iceoryx shared memory, runtime/iox/iox_bus.hpp).
bool IsIoxUrl(const std::string& url);

// The value of parameter `key` of `url` as an integer in [lo, hi]; BusError naming the URL, the parameter
// and the range otherwise. Header-only: the DDS and iceoryx buses use it without linking the runtime.
inline long long UrlInteger(const std::string& url, const std::string& key, const std::string& value, long long lo,
                            long long hi) {
  try {
    size_t used = 0;
    const long long v = std::stoll(value, &used);
    if (used == value.size() && v >= lo && v <= hi) return v;
  } catch (const std::exception&) {
  }
  throw BusError("bus URL '" + url + "': " + key + "=" + value + " is not an integer in [" + std::to_string(lo) +
                 ", " + std::to_string(hi) + "]");
}

}  // namespace fusecal
