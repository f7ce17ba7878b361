// Reading MCAP record fields (little-endian integers, uint32-prefixed strings) from bytes whose length the
// caller checked, with every read bounds-checked: a field running past its record is an McapError.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace fusecal::mcap {

// A fault in the file's bytes, described without the file name or offset: the scan adds both where it
// catches it, so the parsing below does not build strings on the good path.
class McapError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline uint64_t LoadLe(const uint8_t* p, int bytes) {
  uint64_t value = 0;
  for (int i = bytes - 1; i >= 0; --i) value = (value << 8) | p[i];
  return value;
}

class FieldReader {
 public:
  FieldReader(const uint8_t* data, uint64_t size, const char* record) : data_(data), size_(size), record_(record) {}

  uint16_t U16() { return static_cast<uint16_t>(LoadLe(Take(2), 2)); }
  uint32_t U32() { return static_cast<uint32_t>(LoadLe(Take(4), 4)); }
  uint64_t U64() { return LoadLe(Take(8), 8); }
  std::string String() {
    const uint32_t length = U32();
    const uint8_t* p = Take(length);
    return std::string(reinterpret_cast<const char*>(p), length);
  }
  // Skips a uint32-prefixed field (bytes, map).
  void SkipPrefixed() { Take(U32()); }
  const uint8_t* Take(uint64_t n) {
    if (n > size_ - position_)
      throw McapError(std::string(record_) + " record: a field of " + std::to_string(n) + " bytes at byte " +
                      std::to_string(position_) + " runs past the record's " + std::to_string(size_) + " bytes");
    const uint8_t* p = data_ + position_;
    position_ += n;
    return p;
  }
  uint64_t position() const { return position_; }
  uint64_t remaining() const { return size_ - position_; }

 private:
  const uint8_t* data_;
  uint64_t size_;
  uint64_t position_ = 0;
  const char* record_;
};

}  // namespace fusecal::mcap
