// Reading and changing the query parameters of a bus URL (udpm://...?ttl=0, dds://?domain=0&shm=1).
#pragma once

#include <algorithm>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

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
  throw BusError("bus URL '" + url + "': " + key + "=" + value + " is not an integer in [" + std::to_string(lo) + ", " +
                 std::to_string(hi) + "]");
}

// A bus URL taken apart and checked: the scheme, the address, and every query option against the list
// of what that scheme takes, with its range. The one parser for bus URLs: `run` and `doctor` call it
// before any process starts, MakeBus before any bus opens, and the DDS and iceoryx buses read their
// options from it. file:// and tcpq:// options are LCM's own and pass through unchecked.
struct ParsedBusUrl {
  std::string url, scheme, address;
  std::map<std::string, long long> options;  // as given, checked

  long long Get(const std::string& key, long long fallback) const {
    const auto it = options.find(key);
    return it == options.end() ? fallback : it->second;
  }
};

struct BusUrlOption {
  const char* key;
  long long lo, hi;
};

// What each scheme takes. iceoryx's max= stops short of 4 GiB by its chunk header (64 bytes).
inline const std::map<std::string, std::vector<BusUrlOption>>& BusUrlOptions() {
  static const std::map<std::string, std::vector<BusUrlOption>> kOptions = {
      {"udpm", {{"ttl", 0, 255}, {"recv_buf_size", 1, (1ll << 31) - 1}}},
      {"memq", {}},
      // depth: iceoryx (under DDS shared memory too) caps a subscriber queue at 256.
      {"dds",
       {{"domain", 0, 232}, {"shm", 0, 1}, {"depth", 1, 256}, {"bulk_depth", 1, 256}, {"shm_max", 1024, 2147483647}}},
      {"iox", {{"depth", 1, 256}, {"bulk_depth", 1, 256}, {"max", 1024, 4294967295ll - 64}, {"self", 0, 1}}},
      {"file", {}},
      {"tcpq", {}},
  };
  return kOptions;
}

inline std::string BusUrlSchemes() {
  return "udpm:// (LCM UDP multicast), memq:// (LCM in-process), file:// (LCM log), tcpq:// (LCM over TCP), "
         "dds:// (Cyclone DDS), iox:// (iceoryx shared memory, zero-copy)";
}

// Throws BusError naming the URL and what is wrong: no scheme, an unknown one, an address where the
// scheme takes none (dds, iox) or none where it needs one (udpm), an unknown option, a value out of range.
inline ParsedBusUrl ParseBusUrl(const std::string& url) {
  ParsedBusUrl parsed;
  parsed.url = url;
  const auto scheme_end = url.find("://");
  if (scheme_end == std::string::npos)
    throw BusError("bus URL '" + url + "' has no scheme (expected one of " + BusUrlSchemes() + ")");
  parsed.scheme = url.substr(0, scheme_end);
  const auto known = BusUrlOptions().find(parsed.scheme);
  if (known == BusUrlOptions().end())
    throw BusError("bus URL '" + url + "': unknown transport '" + parsed.scheme + "' (expected one of " +
                   BusUrlSchemes() + ")");
  const std::string rest = url.substr(scheme_end + 3);
  const auto question = rest.find('?');
  parsed.address = rest.substr(0, question);
  if (parsed.scheme == "file" || parsed.scheme == "tcpq") return parsed;
  if ((parsed.scheme == "dds" || parsed.scheme == "iox") && !parsed.address.empty() && parsed.address != "/")
    throw BusError("bus URL '" + url + "': " + parsed.scheme + ":// takes no address ('" + parsed.address +
                   "'); give options only, e.g. " + parsed.scheme + "://?depth=16");
  if (parsed.scheme == "udpm" && parsed.address.find(':') == std::string::npos)
    throw BusError("bus URL '" + url + "': udpm:// needs GROUP:PORT, e.g. udpm://239.255.76.67:7667?ttl=0");
  const std::string query = question == std::string::npos ? "" : rest.substr(question + 1);
  for (size_t pos = 0; pos <= query.size();) {
    const size_t amp = std::min(query.find('&', pos), query.size());
    const std::string item = query.substr(pos, amp - pos);
    pos = amp + 1;
    if (item.empty()) continue;
    const auto eq = item.find('=');
    const std::string key = item.substr(0, eq), value = eq == std::string::npos ? "" : item.substr(eq + 1);
    std::string accepted;
    const BusUrlOption* option = nullptr;
    for (const BusUrlOption& o : known->second) {
      accepted += (accepted.empty() ? "" : ", ") + std::string(o.key) + "=";
      if (key == o.key) option = &o;
    }
    if (!option) {
      if (parsed.scheme == "udpm" &&
          (key == "reliable" || key == "loss" || key == "jitter_ms" || key == "fragment_kb" || key == "history_mb" ||
           key == "give_up_s" || key == "loss_seed"))
        throw BusError("bus URL '" + url + "': udpm:// carries plain LCM and has no " + key +
                       "=; for lossy or routed links and several hosts use dds:// (reliable QoS)");
      throw BusError("bus URL '" + url + "': unknown parameter '" + key + "' (" + parsed.scheme + ":// takes " +
                     (accepted.empty() ? std::string("none") : accepted) + ")");
    }
    parsed.options[key] = UrlInteger(url, key, value, option->lo, option->hi);
  }
  return parsed;
}

}  // namespace fusecal
