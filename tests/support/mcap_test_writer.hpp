// A small MCAP writer for tests (the format: https://mcap.dev/spec), written apart from the reader in
// runtime/io/importers so that each checks the other: chunks uncompressed, zstd or lz4 (frame format), with
// message indexes, a summary (schemas, channels, statistics, chunk indexes, summary offsets) or none.
// It also returns where its records are, so that tests can damage them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace fusecal::testing {

struct BagTopic {
  std::string name;  // "/camera/image_raw"
  std::string type;  // "sensor_msgs/msg/Image"
  std::string serialization_format = "cdr";
};

struct BagMessage {
  size_t topic = 0;  // index into the topics
  int64_t log_time_ns = 0;
  std::vector<uint8_t> data;
};

struct McapWriteOptions {
  // "", "zstd" or "lz4"; any other name is written as given over uncompressed records (an unknown one).
  std::string compression = "zstd";
  bool chunked = true;
  size_t messages_per_chunk = 4;
  bool summary = true;  // without: Data End, then a Footer with no summary, then the magic
  bool crc = true;      // chunk CRCs (0 = not given)
};

struct McapTestFile {
  std::vector<uint8_t> bytes;
  std::vector<uint64_t> chunk_offsets;    // of each Chunk record
  std::vector<uint64_t> message_offsets;  // of each Message record outside chunks
  uint64_t data_end_offset = 0;           // of the Data End record
};

// Messages are written in the order given (log times need not be sorted).
McapTestFile WriteMcap(const std::vector<BagTopic>& topics, const std::vector<BagMessage>& messages,
                       const McapWriteOptions& options = McapWriteOptions());

// Offsets of a Chunk record's fields: uncompressed_crc, the compression name's length, records' length.
constexpr uint64_t kChunkCrcField = 9 + 24;
constexpr uint64_t kChunkCompressionField = 9 + 28;

void WriteBytes(const std::string& path, const std::vector<uint8_t>& bytes);
std::vector<uint8_t> ReadBytes(const std::string& path);

}  // namespace fusecal::testing
