#include "runtime/channel_pattern.hpp"

#include <re2/re2.h>

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

// What a pattern may cost to compile: RE2 refuses larger programs with "pattern too large".
constexpr int64_t kMaxPatternMemory = 8 << 20;

}  // namespace

ChannelPattern::ChannelPattern(const std::string& pattern, const std::string& user)
    : pattern_(pattern), plain_(IsPlainName(pattern)) {
  if (plain_) return;
  const std::string prefix = user + ": '" + pattern.substr(0, 80) + (pattern.size() > 80 ? "...'" : "'");
  if (pattern.size() > kMaxPatternBytes)
    throw BusError(prefix + " is " + std::to_string(pattern.size()) + " bytes long; a channel pattern has at most " +
                   std::to_string(kMaxPatternBytes));
  RE2::Options options;
  options.set_log_errors(false);
  options.set_max_mem(kMaxPatternMemory);
  auto regex = std::make_shared<const RE2>(pattern, options);
  if (!regex->ok()) throw BusError(prefix + " is not a valid regular expression: " + regex->error());
  regex_ = std::move(regex);
}

bool ChannelPattern::Matches(const std::string& channel) const {
  return plain_ ? channel == pattern_ : RE2::FullMatch(channel, *regex_);
}

}  // namespace fusecal
