// The size a compressed image (JPEG, PNG) declares in its header, read without decoding it: the
// conversions check it before OpenCV allocates the image (a 1 KB JPEG can declare 60000 x 60000).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace fusecal {

struct ImageSize {
  int width = 0;
  int height = 0;
};

// For `encoding` "jpeg" (the size in the first SOF marker) or "png" (IHDR); nullopt when the bytes do
// not start like that format or the header is cut short, malformed or declares a zero size.
std::optional<ImageSize> CompressedImageSize(const std::vector<uint8_t>& data, const std::string& encoding);

}  // namespace fusecal
