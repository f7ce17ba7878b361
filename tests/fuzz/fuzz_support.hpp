// What the fuzz entries share: files for decoders that read a path, and the rule that a std::exception
// is a rejection, not a finding (fuzz_entries.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>

namespace fusecal::fuzz {

// Writes the bytes to `name` in a folder of this process ($TMPDIR or /tmp, fusecal-fuzz-<pid>; removed
// at exit) and returns its path. The same name is overwritten by the next input.
std::string WriteScratchFile(const std::string& name, const uint8_t* data, size_t size);
// The folder itself (created on first use).
std::string ScratchFolder();

// Runs `decode`; an exception derived from std::exception is the decoder's rejection of the input. Any
// other exception escapes (libFuzzer reports it as a crash).
template <typename F>
void IgnoringRejection(F&& decode) {
  try {
    decode();
  } catch (const std::exception&) {
  }
}

}  // namespace fusecal::fuzz
