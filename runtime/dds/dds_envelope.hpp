// What DdsBus reads from a DDS sample (fusecal::lcm_message, fusecal_bytes.idl) and from discovery besides
// the LCM bytes: the topic name of a channel and back, and the per-writer sequence numbers whose gaps
// count the samples a reader lost. Pure functions of their input (fuzzed: tests/fuzz, tools/fuzz).
#pragma once

#include <cstdint>
#include <map>
#include <string>

namespace fusecal::dds {

// LCM channel <-> DDS topic name: letters, digits, '_' and '/' are kept, other bytes become _xHH; a name
// that is empty or starts with a digit gets a leading '_'.
std::string TopicName(const std::string& channel);
// The channel of a topic name (from a discovered writer: any text).
std::string ChannelName(const std::string& topic);

// Sequence numbers count per writer from 1: a gap means samples were overwritten in a history (KEEP_LAST
// under overload) or dropped from a full shared-memory queue before this reader took them.
class SequenceGaps {
 public:
  // Returns how many samples of `writer` were skipped before `sequence` (0 for the first one seen, for
  // the next one and for a repeated or older one).
  uint64_t Count(uint64_t writer, uint64_t sequence);

 private:
  std::map<uint64_t, uint64_t> last_seen_;  // by writer: the highest sequence number read
};

}  // namespace fusecal::dds
