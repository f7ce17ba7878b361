// Reading and changing the query parameters of a bus URL (udpm://...?ttl=0, dds://?domain=0&shm=1).
#pragma once

#include <string>

namespace fusecal {

// The value of `key=` in the query of a URL, or empty.
std::string UrlParameter(const std::string& url, const std::string& key);

// The URL with `key=value` in its query: replaced where present, appended otherwise.
std::string WithUrlParameter(const std::string& url, const std::string& key, const std::string& value);

// A dds:// URL asking for shared memory (shm=1).
bool IsSharedMemoryDdsUrl(const std::string& url);

// An iox:// URL (iceoryx shared memory, runtime/iox/iox_bus.hpp).
bool IsIoxUrl(const std::string& url);

}  // namespace fusecal
