// Fuzz entry of the motions CSV of `fusecal handeye --motions FILE.csv` (fuzz_entries.hpp): the bytes
// are the whole file.
#include <string>

#include "fuzz_entries.hpp"
#include "fuzz_support.hpp"
#include "stages/handeye/node/motion_csv.hpp"

namespace fusecal::fuzz {

int FuzzOneMotionCsv(const uint8_t* data, size_t size) {
  const std::string path = WriteScratchFile("motions.csv", data, size);
  IgnoringRejection([&] { ReadMotionCsv(path, /*camera_scaled=*/false); });
  return 0;
}

}  // namespace fusecal::fuzz
