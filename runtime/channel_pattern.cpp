#include "runtime/channel_pattern.hpp"

#include <algorithm>
#include <cctype>

#include "runtime/bus_error.hpp"

namespace fusecal {

namespace {

bool IsPlainName(const std::string& channel) {
  return !channel.empty() && std::all_of(channel.begin(), channel.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '_' || c == '-' || c == '/';
  });
}

}  // namespace

ChannelPattern::ChannelPattern(const std::string& pattern, const std::string& transport, std::regex::flag_type grammar)
    : pattern_(pattern), plain_(IsPlainName(pattern)) {
  if (plain_) return;
  try {
    regex_ = std::regex(pattern, grammar);
  } catch (const std::regex_error& e) {
    throw BusError(transport + " subscribe: '" + pattern + "' is not a valid regular expression: " + e.what());
  }
}

}  // namespace fusecal
