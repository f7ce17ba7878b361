// The layout of an IoxBus chunk and the checks on it, without any iceoryx call (shared by the bus and the
// raw-iceoryx row of tools/bench-transport, and testable without RouDi).
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

namespace fusecal::iox {

// The first bytes of every chunk; the LCM bytes follow at offset sizeof(IoxChunkHeader) (8-aligned).
struct IoxChunkHeader {
  uint64_t magic = 0;     // kChunkMagic: chunks of another writer on the same service are ignored
  uint64_t origin = 0;    // the publishing bus: (pid << 20) | bus number in that process
  uint64_t sequence = 0;  // per publisher (origin and channel), from 1
  int64_t utime = 0;      // publish time, system clock
  uint64_t size = 0;      // LCM bytes that follow
};
inline constexpr uint64_t kChunkMagic = 0x31786f696c6366ull;  // "fclox1"
inline constexpr size_t kChunkHeaderBytes = sizeof(IoxChunkHeader);
static_assert(kChunkHeaderBytes % 8 == 0, "the LCM bytes stay 8-aligned");

// iceoryx's service, instance and event strings hold at most 100 bytes.
inline constexpr size_t kMaxIdBytes = 100;
inline constexpr const char* kService = "fusecal";
inline constexpr const char* kEvent = "lcm";

// The header of a chunk of `chunk_bytes` bytes, or null when it is not one of ours (too short, another
// magic, a size that does not fit the chunk).
const IoxChunkHeader* ParseChunk(const void* chunk, size_t chunk_bytes);

// Empty when `channel` can be a service instance; otherwise why not (one line).
std::string CheckChannelName(const std::string& channel);

// Sequence numbers count per publisher from 1: a gap means a full subscriber queue dropped chunks.
class SequenceGaps {
 public:
  // Chunks of `publisher` skipped before `sequence` (0 for the first one seen, the next, or an older one).
  uint64_t Count(uint64_t publisher, uint64_t sequence);

 private:
  std::map<uint64_t, uint64_t> last_seen_;
};

}  // namespace fusecal::iox
