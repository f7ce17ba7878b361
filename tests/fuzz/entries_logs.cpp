// Fuzz entries of LCM logs (fuzz_entries.hpp): the bytes are a whole log file.
#include <string>

#include "fuzz_entries.hpp"
#include "fuzz_support.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/formats/ground_truth.hpp"
#include "stages/formats/message_json.hpp"

namespace fusecal::fuzz {

int FuzzOneLcmLog(const uint8_t* data, size_t size) {
  const std::string path = WriteScratchFile("fuzz.log", data, size);
  IgnoringRejection([&] {
    LogReader reader(path);
    while (auto event = reader.Next()) {  // `fusecal log dump`: every event as JSON
      std::string error;
      IgnoringRejection([&] { DecodeToJson(event->data.data(), event->data.size(), false, &error); });
    }
    reader.problems();
  });
  return 0;
}

int FuzzOneGroundTruthLog(const uint8_t* data, size_t size) {
  const std::string path = WriteScratchFile("fuzz-truth.log", data, size);
  IgnoringRejection([&] { ReadReferenceExtrinsic(path); });      // `fusecal evaluate --reference LOG`
  IgnoringRejection([&] { ReadReference(path, int64_t{25}); });  // ... --at-utime 25
  return 0;
}

}  // namespace fusecal::fuzz
