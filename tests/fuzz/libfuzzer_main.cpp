// The libFuzzer entry of one fuzz_<name> executable: FUSECAL_FUZZ_ENTRY names its function in
// fuzz_entries.hpp (set per executable by tests/fuzz/CMakeLists.txt).
#include "fuzz_entries.hpp"

#ifndef FUSECAL_FUZZ_ENTRY
#error "FUSECAL_FUZZ_ENTRY must name a function of fuzz_entries.hpp"
#endif

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return fusecal::fuzz::FUSECAL_FUZZ_ENTRY(data, size);
}
