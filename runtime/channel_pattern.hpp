// The channel of a subscription (Bus::SubscribeRaw), or the --channel of `fusecal log dump`: a plain name
// (letters, digits, '_', '-', '/') matches itself; anything else is a regular expression over the whole
// channel name, as LCM matches. Patterns come from users, so they are RE2's: matching takes time linear
// in the channel's length and bounded memory whatever the pattern (no backtracking blow-up such as
// `(a|aa)*c`, no stack overflow on deep nesting). Shared by the LCM, DDS and iceoryx buses.
#pragma once

#include <memory>
#include <string>

namespace re2 {
class RE2;
}

namespace fusecal {

class ChannelPattern {
 public:
  // Longest pattern accepted.
  static constexpr size_t kMaxPatternBytes = 4096;

  // Throws BusError "<user>: '<pattern>' is not a valid regular expression: ..." (RE2's reason,
  // e.g. "bad repetition operator" or "expression nests too deeply"), and for patterns over
  // kMaxPatternBytes.
  ChannelPattern(const std::string& pattern, const std::string& user);

  const std::string& text() const { return pattern_; }
  bool plain() const { return plain_; }
  bool Matches(const std::string& channel) const;

 private:
  std::string pattern_;
  bool plain_;
  std::shared_ptr<const re2::RE2> regex_;  // shared: patterns are copied into subscriptions
};

}  // namespace fusecal
