#include "runtime/iox/iox_chunk.hpp"

#include <cstring>

namespace fusecal::iox {

const IoxChunkHeader* ParseChunk(const void* chunk, size_t chunk_bytes) {
  if (!chunk || chunk_bytes < kChunkHeaderBytes) return nullptr;
  const auto* header = static_cast<const IoxChunkHeader*>(chunk);
  if (header->magic != kChunkMagic || header->size > chunk_bytes - kChunkHeaderBytes) return nullptr;
  return header;
}

std::string CheckChannelName(const std::string& channel) {
  if (channel.empty()) return "an empty channel name";
  if (channel.size() > kMaxIdBytes)
    return "channel name of " + std::to_string(channel.size()) + " bytes (iceoryx service names hold at most " +
           std::to_string(kMaxIdBytes) + ")";
  if (std::memchr(channel.data(), '\0', channel.size())) return "a channel name with a NUL byte";
  return {};
}

uint64_t SequenceGaps::Count(uint64_t publisher, uint64_t sequence) {
  auto [it, first] = last_seen_.emplace(publisher, sequence);
  if (first) return 0;
  if (sequence <= it->second) return 0;
  const uint64_t skipped = sequence - it->second - 1;
  it->second = sequence;
  return skipped;
}

}  // namespace fusecal::iox
