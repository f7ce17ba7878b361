// The records of an MCAP chunk: uncompressed as stored, or zstd or lz4 (frame format) decompressed into
// exactly the size the chunk declares; and the CRC32 the chunk carries.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace fusecal::mcap {

enum class Compression : uint8_t { kNone, kZstd, kLz4 };

// "", "zstd" or "lz4"; false for any other name.
bool ParseCompression(const std::string& name, Compression& compression);

// The chunk's records from its stored bytes. Throws McapError when the stored bytes do not produce exactly
// uncompressed_size bytes (a truncated or corrupt stream, or a size that lies) or when uncompressed_size
// exceeds limit. The output grows with what the stream actually yields, so a lying size in a small file
// does not allocate it.
std::vector<uint8_t> ChunkRecords(Compression compression, std::vector<uint8_t> stored, uint64_t uncompressed_size,
                                  uint64_t limit);

// CRC-32 (ISO-HDLC, as zlib and the MCAP specification).
uint32_t Crc32(const uint8_t* data, size_t size);

}  // namespace fusecal::mcap
