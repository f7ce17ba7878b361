// The channel of a subscription (Bus::SubscribeRaw): a plain name (letters, digits, '_', '-', '/')
// matches itself; anything else is a regular expression over the whole channel name, as LCM matches.
// Shared by the LCM, DDS and iceoryx buses.
#pragma once

#include <regex>
#include <string>

namespace fusecal {

class ChannelPattern {
 public:
  // Throws BusError "<transport> subscribe: '<pattern>' is not a valid regular expression: ..."
  ChannelPattern(const std::string& pattern, const std::string& transport,
                 std::regex::flag_type grammar = std::regex::ECMAScript);

  const std::string& text() const { return pattern_; }
  bool plain() const { return plain_; }
  bool Matches(const std::string& channel) const {
    return plain_ ? channel == pattern_ : std::regex_match(channel, regex_);
  }

 private:
  std::string pattern_;
  bool plain_;
  std::regex regex_;
};

}  // namespace fusecal
