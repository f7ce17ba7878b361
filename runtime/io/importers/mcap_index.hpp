// What the linear scan of an MCAP file finds (mcap_scan.cpp): the channels, the chunks and where every
// message is, in file order. Internal to the MCAP reader.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "runtime/io/importers/mcap_chunk.hpp"
#include "runtime/io/importers/mcap_reader.hpp"

namespace fusecal::mcap {

constexpr uint32_t kNoChunk = UINT32_MAX;

struct ChunkLocation {
  uint64_t record_offset = 0;  // of the Chunk record, for messages
  uint64_t stored_offset = 0;  // of its (compressed) records
  uint64_t stored_size = 0;
  uint64_t uncompressed_size = 0;
  Compression compression = Compression::kNone;
  // Uncompressed chunks only: the CRC of its records (0: none given), checked when they are read for
  // their messages; the scan reads only the record headers of such a chunk, not the data twice.
  uint32_t crc = 0;
};

struct MessageRef {
  int64_t log_time_ns = 0;
  uint64_t offset = 0;  // of the message data: in the chunk's records, or in the file when chunk == kNoChunk
  uint64_t size = 0;
  uint32_t chunk = kNoChunk;
  uint32_t channel = 0;  // index into channels
};

struct McapIndex {
  std::vector<Channel> channels;
  std::vector<ChunkLocation> chunks;
  std::vector<MessageRef> messages;
  std::vector<std::string> warnings;
};

// Throws std::runtime_error "<name>: <what> at offset <N>".
McapIndex ScanMcap(ByteSource& source, const std::string& name, const Limits& limits);

}  // namespace fusecal::mcap
