#include "runtime/reliable/url_options.hpp"

#include <unistd.h>

#include <set>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace fusecal::reliable {

namespace {

const std::set<std::string>& OurKeys() {
  static const std::set<std::string> keys{"reliable",  "fragment_kb", "history_mb", "give_up_s",
                                          "loss",      "jitter_ms",   "loss_seed"};
  return keys;
}

double Number(const std::string& key, const std::string& text, double low, double high) {
  size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !(value >= low && value <= high))
    throw std::invalid_argument("bus URL parameter " + key + "=" + text + ": expected a number in [" +
                                std::to_string(low) + ", " + std::to_string(high) + "]");
  return value;
}

}  // namespace

UrlOptions ParseUrlOptions(const std::string& url) {
  UrlOptions options;
  options.loss_seed = uint64_t(getpid()) * 0x9e3779b97f4a7c15ull;
  const auto query = url.find('?');
  options.lcm_url = url.substr(0, query);
  if (query == std::string::npos) return options;
  std::vector<std::string> kept;
  std::istringstream params(url.substr(query + 1));
  for (std::string item; std::getline(params, item, '&');) {
    if (item.empty()) continue;
    const auto eq = item.find('=');
    const std::string key = item.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
    if (!OurKeys().count(key)) {
      kept.push_back(item);
      continue;
    }
    if (key == "reliable") {
      if (value != "0" && value != "1") throw std::invalid_argument("bus URL parameter reliable=" + value + ": expected 0 or 1");
      options.reliable = value == "1";
    } else if (key == "fragment_kb") {
      options.sender.fragment_bytes = size_t(Number(key, value, 1, 63) * 1000);
    } else if (key == "history_mb") {
      options.sender.history_bytes = size_t(Number(key, value, 1, 65536) * (1u << 20));
    } else if (key == "give_up_s") {
      options.receiver.give_up_us = int64_t(Number(key, value, 0.1, 86400) * 1e6);
    } else if (key == "loss") {
      options.loss = Number(key, value, 0, 0.5);
    } else if (key == "jitter_ms") {
      options.jitter_us = int64_t(Number(key, value, 0, 10000) * 1000);
    } else if (key == "loss_seed") {
      options.loss_seed = uint64_t(Number(key, value, 0, 9.0e15));
    }
  }
  for (size_t i = 0; i < kept.size(); ++i) options.lcm_url += (i ? "&" : "?") + kept[i];
  return options;
}

}  // namespace fusecal::reliable
