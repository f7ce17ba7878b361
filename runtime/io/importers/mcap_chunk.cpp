#include "runtime/io/importers/mcap_chunk.hpp"

#include <isa-l/crc.h>
#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <memory>

#include "runtime/io/importers/mcap_fields.hpp"

namespace fusecal::mcap {

namespace {

// Output of a decompressing stream: starts small, doubles as the stream fills it, and holds one byte
// more than expected so that a stream yielding too much is seen.
class GrowingOutput {
 public:
  GrowingOutput(uint64_t expected, size_t stored) : expected_(expected) {
    // Ordinary chunks compress well under 64:1, so they are decompressed without a reallocation.
    const uint64_t first = std::max<uint64_t>(uint64_t{1} << 16, uint64_t{stored} * 64);
    bytes_.resize(static_cast<size_t>(std::min(expected_ + 1, first)));
  }
  // Room to write into; grows when full. Throws once the stream has yielded more than expected.
  uint8_t* Room(size_t& room) {
    if (filled_ == bytes_.size()) {
      if (filled_ > expected_)
        throw McapError("chunk decompresses to more than its uncompressed size " + std::to_string(expected_));
      bytes_.resize(static_cast<size_t>(std::min<uint64_t>(expected_ + 1, uint64_t{bytes_.size()} * 2)));
    }
    room = bytes_.size() - filled_;
    return bytes_.data() + filled_;
  }
  void Advance(size_t n) { filled_ += n; }
  bool full() const { return filled_ == bytes_.size(); }
  // The records, once the stream ended (frame_done) with all input read.
  std::vector<uint8_t> Finish(bool frame_done, const char* codec) {
    if (filled_ > expected_)
      throw McapError("chunk decompresses to more than its uncompressed size " + std::to_string(expected_));
    if (!frame_done || filled_ < expected_)
      throw McapError(std::string("truncated chunk: ") + codec + " stream ends after " + std::to_string(filled_) +
                      " of " + std::to_string(expected_) + " uncompressed bytes");
    bytes_.resize(filled_);
    return std::move(bytes_);
  }

 private:
  uint64_t expected_;
  std::vector<uint8_t> bytes_;
  size_t filled_ = 0;
};

std::vector<uint8_t> Zstd(const std::vector<uint8_t>& stored, uint64_t expected) {
  // One context per thread, reset for each chunk: creating one per chunk cost more than decompressing
  // small chunks.
  thread_local std::unique_ptr<ZSTD_DCtx, size_t (*)(ZSTD_DCtx*)> context(ZSTD_createDCtx(), ZSTD_freeDCtx);
  if (!context) throw std::bad_alloc();
  ZSTD_DCtx_reset(context.get(), ZSTD_reset_session_only);
  GrowingOutput output(expected, stored.size());
  ZSTD_inBuffer in{stored.data(), stored.size(), 0};
  size_t hint = 1;
  for (;;) {
    size_t room = 0;
    uint8_t* at = output.Room(room);
    ZSTD_outBuffer out{at, room, 0};
    const size_t in_before = in.pos;
    hint = ZSTD_decompressStream(context.get(), &out, &in);
    if (ZSTD_isError(hint)) throw McapError(std::string("zstd chunk: ") + ZSTD_getErrorName(hint));
    output.Advance(out.pos);
    if (in.pos == in.size && !output.full()) break;                    // all read, and the decoder had room to flush
    if (out.pos == 0 && in.pos == in_before && !output.full()) break;  // no progress: let Finish say why
  }
  return output.Finish(hint == 0 && in.pos == in.size, "zstd");
}

std::vector<uint8_t> Lz4(const std::vector<uint8_t>& stored, uint64_t expected) {
  // One context per thread, reset for each chunk: a new one allocates its block buffers (up to 4 MB for
  // frames with 4 MB blocks, as the MCAP project's writers make) again for every chunk.
  thread_local std::unique_ptr<LZ4F_dctx, size_t (*)(LZ4F_dctx*)> context(nullptr, LZ4F_freeDecompressionContext);
  if (!context) {
    LZ4F_dctx* raw = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION))) throw std::bad_alloc();
    context.reset(raw);
  }
  LZ4F_resetDecompressionContext(context.get());
  GrowingOutput output(expected, stored.size());
  size_t in_pos = 0;
  size_t hint = 1;
  for (;;) {
    size_t room = 0;
    uint8_t* at = output.Room(room);
    size_t in_size = stored.size() - in_pos;
    hint = LZ4F_decompress(context.get(), at, &room, stored.data() + in_pos, &in_size, nullptr);
    if (LZ4F_isError(hint)) throw McapError(std::string("lz4 chunk: ") + LZ4F_getErrorName(hint));
    output.Advance(room);
    in_pos += in_size;
    if (in_pos == stored.size() && !output.full()) break;
    if (room == 0 && in_size == 0 && !output.full()) break;
  }
  return output.Finish(hint == 0 && in_pos == stored.size(), "lz4");
}

}  // namespace

bool ParseCompression(const std::string& name, Compression& compression) {
  if (name.empty())
    compression = Compression::kNone;
  else if (name == "zstd")
    compression = Compression::kZstd;
  else if (name == "lz4")
    compression = Compression::kLz4;
  else
    return false;
  return true;
}

std::vector<uint8_t> ChunkRecords(Compression compression, std::vector<uint8_t> stored, uint64_t uncompressed_size,
                                  uint64_t limit) {
  if (uncompressed_size > limit)
    throw McapError("chunk of " + std::to_string(uncompressed_size) + " uncompressed bytes exceeds the limit of " +
                    std::to_string(limit));
  switch (compression) {
    case Compression::kNone:
      if (stored.size() != uncompressed_size)
        throw McapError("uncompressed chunk of " + std::to_string(stored.size()) +
                        " bytes declares an uncompressed size of " + std::to_string(uncompressed_size));
      return stored;
    case Compression::kZstd:
      return Zstd(stored, uncompressed_size);
    case Compression::kLz4:
      return Lz4(stored, uncompressed_size);
  }
  return {};
}

// ISA-L's CRC32 (the gzip polynomial, as MCAP's) runs at about 8 GB/s with carry-less multiplication
// here, zlib's at 2.7: for an uncompressed bag the check was a tenth of the import's time.
uint32_t Crc32(const uint8_t* data, size_t size) { return crc32_gzip_refl(0, data, size); }

}  // namespace fusecal::mcap
