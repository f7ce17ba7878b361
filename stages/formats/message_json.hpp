// JSON view of every fusecal message, for `fusecal log dump`. The type is recognised from the LCM
// fingerprint in the first 8 bytes of the encoded message.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace fusecal {

using OrderedJson = nlohmann::ordered_json;

struct DecodedMessage {
  std::string type;  // e.g. "fusecal.image_t"
  OrderedJson json;
};

// Decodes a message of any fusecal type. `full` writes bulk arrays (pixels, points) in full, otherwise
// they are shown by length. Returns nullopt with *error set for unknown types or corrupt bytes.
std::optional<DecodedMessage> DecodeToJson(const uint8_t* data, size_t size, bool full, std::string* error);

}  // namespace fusecal
