// Fuzz entry of the iox:// chunk (fuzz_entries.hpp): the bytes are the user payload of one iceoryx chunk
// on a fusecal service, as IoxBus takes it from shared memory that any process attached to RouDi can
// write: the header is checked (ParseChunk), the publisher's sequence gap counted, and the LCM bytes that
// follow handed to the handlers (here: the LCM decoder of every type).
#include <cstring>
#include <string>
#include <vector>

#include "fuzz_entries.hpp"
#include "fuzz_support.hpp"
#include "runtime/iox/iox_chunk.hpp"
#include "stages/formats/message_json.hpp"

namespace fusecal::fuzz {

int FuzzOneIoxChunk(const uint8_t* data, size_t size) {
  // The chunk's bytes are 8-aligned in shared memory: the same here.
  std::vector<uint64_t> aligned((size + 7) / 8 + 1, 0);
  std::memcpy(aligned.data(), data, size);
  const iox::IoxChunkHeader* header = iox::ParseChunk(aligned.data(), size);
  if (!header) return 0;
  iox::SequenceGaps gaps;
  gaps.Count(header->origin, 1);
  gaps.Count(header->origin, header->sequence);
  const auto* bytes = reinterpret_cast<const uint8_t*>(aligned.data()) + iox::kChunkHeaderBytes;
  std::string error;
  IgnoringRejection([&] { DecodeToJson(bytes, static_cast<size_t>(header->size), false, &error); });
  return 0;
}

}  // namespace fusecal::fuzz
