// Fuzz entry of the MCAP reader of rosbag2 bags (fuzz_entries.hpp): the bytes are a whole .mcap file,
// read from memory (no scratch file), every message visited in log-time order.
#include "fuzz_entries.hpp"
#include "fuzz_support.hpp"
#include "runtime/io/importers/mcap_reader.hpp"

namespace fusecal::fuzz {

int FuzzOneMcap(const uint8_t* data, size_t size) {
  IgnoringRejection([&] {
    mcap::Limits limits;
    // Far above the seeds' chunks, far below libFuzzer's memory limit.
    limits.max_chunk_bytes = uint64_t{64} << 20;
    const auto reader = mcap::ReadMcapFromMemory("fuzz.mcap", data, size, limits);
    const auto cursor = reader->Messages({});
    mcap::Message message;
    volatile uint8_t sink = 0;
    while (cursor->Next(message)) {
      // Touch both ends of every message, so that a wrong offset or size is an ASan report.
      if (message.size > 0) sink = sink + message.data[0] + message.data[message.size - 1];
      sink = sink + static_cast<uint8_t>(reader->channels().at(message.channel).topic.size());
    }
  });
  return 0;
}

}  // namespace fusecal::fuzz
