// Fuzz entries of short texts users type or write by hand (fuzz_entries.hpp): bus URLs, channel patterns,
// extrinsics in the export formats, YAML read strictly.
#include <string>

#include "fuzz_entries.hpp"
#include "fuzz_support.hpp"
#include "runtime/bus_url.hpp"
#include "runtime/channel_pattern.hpp"
#include "runtime/strict_yaml.hpp"
#include "stages/formats/extrinsic_formats.hpp"

namespace fusecal::fuzz {

namespace {

std::string Text(const uint8_t* data, size_t size) { return std::string(reinterpret_cast<const char*>(data), size); }

}  // namespace

int FuzzOneBusUrl(const uint8_t* data, size_t size) {
  IgnoringRejection([&] {
    const ParsedBusUrl parsed = ParseBusUrl(Text(data, size));
    WithUrlParameter(parsed.url, "shm", "0");
  });
  return 0;
}

// The first line is the pattern, the rest channel names to match against it.
int FuzzOneChannelPattern(const uint8_t* data, size_t size) {
  const std::string text = Text(data, size);
  const size_t eol = text.find('\n');
  IgnoringRejection([&] {
    const ChannelPattern pattern(text.substr(0, eol), "fuzz");
    for (size_t pos = eol; pos != std::string::npos && pos < text.size();) {
      const size_t next = text.find('\n', pos + 1);
      pattern.Matches(text.substr(pos + 1, next == std::string::npos ? std::string::npos : next - pos - 1));
      pos = next;
    }
  });
  return 0;
}

// The first byte chooses the format.
int FuzzOneExtrinsicText(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const auto& formats = ExportFormats();
  const std::string& format = formats[data[0] % formats.size()];
  IgnoringRejection([&] { ParseExportedExtrinsic(Text(data + 1, size - 1), format); });
  return 0;
}

int FuzzOneStrictYaml(const uint8_t* data, size_t size) {
  IgnoringRejection([&] { LoadStrictYaml(Text(data, size), "fuzz.yaml"); });
  return 0;
}

}  // namespace fusecal::fuzz
