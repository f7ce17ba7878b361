#include "runtime/dds/dds_envelope.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>

namespace fusecal::dds {

std::string TopicName(const std::string& channel) {
  std::string topic;
  for (unsigned char c : channel) {
    if (std::isalnum(c) || c == '_' || c == '/') {
      topic += static_cast<char>(c);
    } else {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "_x%02X", c);
      topic += escaped;
    }
  }
  if (topic.empty() || std::isdigit(static_cast<unsigned char>(topic[0]))) topic = "_" + topic;
  return topic;
}

std::string ChannelName(const std::string& topic) {
  std::string name = topic;
  if (!name.empty() && name[0] == '_' && name.size() > 1 && std::isdigit(static_cast<unsigned char>(name[1])))
    name.erase(0, 1);
  std::string channel;
  for (size_t i = 0; i < name.size(); ++i) {
    if (name[i] == '_' && i + 3 < name.size() && name[i + 1] == 'x' &&
        std::isxdigit(static_cast<unsigned char>(name[i + 2])) &&
        std::isxdigit(static_cast<unsigned char>(name[i + 3]))) {
      channel += static_cast<char>(std::stoi(name.substr(i + 2, 2), nullptr, 16));
      i += 3;
    } else {
      channel += name[i];
    }
  }
  return channel;
}

uint64_t SequenceGaps::Count(uint64_t writer, uint64_t sequence) {
  auto [it, first] = last_seen_.emplace(writer, sequence);
  if (first) return 0;
  const uint64_t skipped = sequence > it->second + 1 ? sequence - it->second - 1 : 0;
  it->second = std::max(it->second, sequence);
  return skipped;
}

}  // namespace fusecal::dds
