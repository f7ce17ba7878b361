// The bytes of an MCAP file, read by offset: from disk (pread, so a multi-GB bag is never held whole) or
// from memory (the fuzz entry). Reads are checked against the size; the count of bytes read is kept for
// MB/s reports.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace fusecal::mcap {

class ByteSource {
 public:
  virtual ~ByteSource() = default;
  virtual uint64_t size() const = 0;
  // Fills out[0, n) from offset; throws std::runtime_error (naming the file, for a file) if the range is
  // not in it or the read fails.
  virtual void ReadAt(uint64_t offset, uint64_t n, uint8_t* out) = 0;
  std::vector<uint8_t> Read(uint64_t offset, uint64_t n) {
    std::vector<uint8_t> bytes(n);
    ReadAt(offset, n, bytes.data());
    return bytes;
  }
  uint64_t bytes_read() const { return bytes_read_; }

 protected:
  uint64_t bytes_read_ = 0;
};

// Throws std::runtime_error naming the path when it cannot be opened or is not a regular file.
std::unique_ptr<ByteSource> OpenFileSource(const std::string& path);
// The bytes are copied.
std::unique_ptr<ByteSource> MemorySource(const uint8_t* data, size_t size);

}  // namespace fusecal::mcap
