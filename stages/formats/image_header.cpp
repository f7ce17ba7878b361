#include "stages/formats/image_header.hpp"

namespace fusecal {

namespace {

uint32_t BigEndian(const uint8_t* p, int bytes) {
  uint32_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}

std::optional<ImageSize> Checked(uint32_t width, uint32_t height) {
  if (width == 0 || height == 0 || width > 0x7fffffff || height > 0x7fffffff) return std::nullopt;
  return ImageSize{static_cast<int>(width), static_cast<int>(height)};
}

// Signature, then the IHDR chunk first: length (4), "IHDR", width (4), height (4).
std::optional<ImageSize> PngSize(const std::vector<uint8_t>& d) {
  static const uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (d.size() < 24) return std::nullopt;
  for (int i = 0; i < 8; ++i)
    if (d[i] != kSignature[i]) return std::nullopt;
  if (d[12] != 'I' || d[13] != 'H' || d[14] != 'D' || d[15] != 'R') return std::nullopt;
  return Checked(BigEndian(&d[16], 4), BigEndian(&d[20], 4));
}

bool IsStartOfFrame(uint8_t marker) {
  return marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
}

// SOI, then marker segments up to the first SOF: precision (1), height (2), width (2).
std::optional<ImageSize> JpegSize(const std::vector<uint8_t>& d) {
  if (d.size() < 4 || d[0] != 0xff || d[1] != 0xd8) return std::nullopt;
  size_t pos = 2;
  while (pos + 4 <= d.size()) {
    if (d[pos] != 0xff) return std::nullopt;
    const uint8_t marker = d[pos + 1];
    if (marker == 0xff) {  // fill byte
      ++pos;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd8)) {  // no length: TEM, RSTn, SOI
      pos += 2;
      continue;
    }
    if (marker == 0xd9 || marker == 0xda) return std::nullopt;  // EOI or SOS before any frame
    const uint32_t length = BigEndian(&d[pos + 2], 2);
    if (length < 2) return std::nullopt;
    if (IsStartOfFrame(marker)) {
      if (length < 7 || pos + 9 > d.size()) return std::nullopt;
      return Checked(BigEndian(&d[pos + 7], 2), BigEndian(&d[pos + 5], 2));
    }
    pos += 2 + length;
  }
  return std::nullopt;
}

}  // namespace

std::optional<ImageSize> CompressedImageSize(const std::vector<uint8_t>& data, const std::string& encoding) {
  if (encoding == "jpeg") return JpegSize(data);
  if (encoding == "png") return PngSize(data);
  return std::nullopt;
}

}  // namespace fusecal
