#include "runtime/bus_url.hpp"

#include <sstream>
#include <vector>

namespace fusecal {

std::string UrlParameter(const std::string& url, const std::string& key) {
  const auto query = url.find('?');
  if (query == std::string::npos) return {};
  std::istringstream params(url.substr(query + 1));
  std::string item;
  while (std::getline(params, item, '&')) {
    const auto eq = item.find('=');
    if (eq != std::string::npos && item.substr(0, eq) == key) return item.substr(eq + 1);
  }
  return {};
}

std::string WithUrlParameter(const std::string& url, const std::string& key, const std::string& value) {
  const auto query = url.find('?');
  const std::string base = url.substr(0, query);
  std::vector<std::string> items;
  bool replaced = false;
  if (query != std::string::npos) {
    std::istringstream params(url.substr(query + 1));
    std::string item;
    while (std::getline(params, item, '&')) {
      if (item.empty()) continue;
      if (item.substr(0, item.find('=')) == key) {
        item = key + "=" + value;
        replaced = true;
      }
      items.push_back(item);
    }
  }
  if (!replaced) items.push_back(key + "=" + value);
  std::string result = base + "?";
  for (size_t i = 0; i < items.size(); ++i) result += (i ? "&" : "") + items[i];
  return result;
}

bool IsSharedMemoryDdsUrl(const std::string& url) {
  return url.rfind("dds://", 0) == 0 && UrlParameter(url, "shm") == "1";
}

bool IsIoxUrl(const std::string& url) { return url.rfind("iox://", 0) == 0; }

}  // namespace fusecal
