#include "tests/support/mcap_test_writer.hpp"

#include <lz4frame.h>
#include <zlib.h>
#include <zstd.h>

#include <fstream>
#include <map>
#include <set>
#include <stdexcept>

namespace fusecal::testing {

namespace {

const std::vector<uint8_t> kMagic = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
enum Opcode : uint8_t {
  kHeader = 1,
  kFooter,
  kSchema,
  kChannel,
  kMessage,
  kChunk,
  kMessageIndex,
  kChunkIndex,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F
};

struct Bytes {
  std::vector<uint8_t> b;
  Bytes& Int(uint64_t value, int size) {
    for (int i = 0; i < size; ++i) b.push_back(static_cast<uint8_t>(value >> (8 * i)));
    return *this;
  }
  Bytes& U8Op(uint8_t v) { return Int(v, 1); }
  Bytes& U16(uint64_t v) { return Int(v, 2); }
  Bytes& U32(uint64_t v) { return Int(v, 4); }
  Bytes& U64(uint64_t v) { return Int(v, 8); }
  Bytes& Raw(const std::vector<uint8_t>& data) {
    b.insert(b.end(), data.begin(), data.end());
    return *this;
  }
  Bytes& String(const std::string& s) {
    U32(s.size());
    b.insert(b.end(), s.begin(), s.end());
    return *this;
  }
  Bytes& Record(uint8_t op, const Bytes& content) {
    b.push_back(op);
    U64(content.b.size());
    return Raw(content.b);
  }
};

std::vector<uint8_t> Compress(const std::string& compression, const std::vector<uint8_t>& data) {
  if (compression == "zstd") {
    std::vector<uint8_t> out(ZSTD_compressBound(data.size()));
    const size_t n = ZSTD_compress(out.data(), out.size(), data.data(), data.size(), 3);
    if (ZSTD_isError(n)) throw std::runtime_error("zstd compression failed");
    out.resize(n);
    return out;
  }
  if (compression == "lz4") {
    std::vector<uint8_t> out(LZ4F_compressFrameBound(data.size(), nullptr));
    const size_t n = LZ4F_compressFrame(out.data(), out.size(), data.data(), data.size(), nullptr);
    if (LZ4F_isError(n)) throw std::runtime_error("lz4 compression failed");
    out.resize(n);
    return out;
  }
  return data;  // "" or a name the reader does not know
}

Bytes SchemaRecord(const std::vector<BagTopic>& topics, size_t t) {
  Bytes content;
  content.U16(t + 1).String(topics[t].type).String("ros2msg").String("# a definition");
  return Bytes().Record(kSchema, content);
}

Bytes ChannelRecord(const std::vector<BagTopic>& topics, size_t t) {
  Bytes metadata;
  metadata.String("offered_qos_profiles").String("");
  Bytes content;
  content.U16(t).U16(t + 1).String(topics[t].name).String(topics[t].serialization_format);
  content.U32(metadata.b.size()).Raw(metadata.b);
  return Bytes().Record(kChannel, content);
}

Bytes MessageRecord(const BagMessage& m, uint32_t sequence) {
  Bytes content;
  content.U16(m.topic).U32(sequence).U64(m.log_time_ns).U64(m.log_time_ns).Raw(m.data);
  return Bytes().Record(kMessage, content);
}

struct ChunkIndexEntry {
  uint64_t start = 0, end = 0, offset = 0, length = 0, index_length = 0, stored = 0, uncompressed = 0;
  std::map<uint16_t, uint64_t> index_offsets;
};

// Writes what the file has so far and what the summary needs to know.
class Writer {
 public:
  Writer(const std::vector<BagTopic>& topics, const McapWriteOptions& options) : topics_(topics), options_(options) {
    out_.Raw(kMagic);
    Bytes header;
    header.String("ros2").String("fusecal mcap_test_writer");
    out_.Record(kHeader, header);
  }

  void Unchunked(const std::vector<BagMessage>& messages) {
    for (size_t i = 0; i < messages.size(); ++i) {
      Define(messages[i].topic, out_);
      file_.message_offsets.push_back(out_.b.size());
      out_.Raw(MessageRecord(messages[i], i).b);
    }
  }

  void Chunk(const std::vector<BagMessage>& messages, size_t first, size_t count);
  McapTestFile Finish(const std::vector<BagMessage>& messages);

 private:
  void Define(size_t topic, Bytes& into) {
    if (!defined_.insert(topic).second) return;
    into.Raw(SchemaRecord(topics_, topic).b).Raw(ChannelRecord(topics_, topic).b);
  }
  void Summary(const std::vector<BagMessage>& messages);
  // Ends a group of summary records of one opcode, begun at `start`.
  void Group(uint8_t op, uint64_t start) { groups_.U8Op(op).U64(start).U64(out_.b.size() - start); }

  const std::vector<BagTopic>& topics_;
  const McapWriteOptions& options_;
  Bytes out_;
  McapTestFile file_;
  std::set<size_t> defined_;
  std::vector<ChunkIndexEntry> chunk_indexes_;
  Bytes groups_;  // the contents of the Summary Offset records
};

void Writer::Chunk(const std::vector<BagMessage>& messages, size_t first, size_t count) {
  Bytes records;
  std::map<uint16_t, Bytes> index;  // per channel: (log time, offset) pairs
  ChunkIndexEntry entry;
  entry.start = UINT64_MAX;
  for (size_t i = first; i < first + count; ++i) {
    Define(messages[i].topic, records);
    const uint64_t log_time = static_cast<uint64_t>(messages[i].log_time_ns);
    index[static_cast<uint16_t>(messages[i].topic)].U64(log_time).U64(records.b.size());
    entry.start = std::min(entry.start, log_time);
    entry.end = std::max(entry.end, log_time);
    records.Raw(MessageRecord(messages[i], i).b);
  }
  const std::vector<uint8_t> stored = Compress(options_.compression, records.b);
  Bytes content;
  content.U64(entry.start).U64(entry.end).U64(records.b.size());
  content.U32(options_.crc ? crc32_z(0, records.b.data(), records.b.size()) : 0);
  content.String(options_.compression).U64(stored.size()).Raw(stored);
  entry.offset = out_.b.size();
  entry.stored = stored.size();
  entry.uncompressed = records.b.size();
  file_.chunk_offsets.push_back(entry.offset);
  out_.Record(kChunk, content);
  entry.length = out_.b.size() - entry.offset;
  for (auto& [channel, pairs] : index) {
    entry.index_offsets[channel] = out_.b.size();
    Bytes index_content;
    index_content.U16(channel).U32(pairs.b.size()).Raw(pairs.b);
    out_.Record(kMessageIndex, index_content);
  }
  entry.index_length = out_.b.size() - entry.offset - entry.length;
  chunk_indexes_.push_back(entry);
}

void Writer::Summary(const std::vector<BagMessage>& messages) {
  Bytes statistics, counts_map;
  std::map<uint16_t, uint64_t> counts;
  uint64_t start = UINT64_MAX, end = 0;
  for (const BagMessage& m : messages) {
    ++counts[static_cast<uint16_t>(m.topic)];
    start = std::min<uint64_t>(start, m.log_time_ns);
    end = std::max<uint64_t>(end, m.log_time_ns);
  }
  uint64_t group = out_.b.size();
  for (size_t t = 0; t < topics_.size(); ++t) out_.Raw(SchemaRecord(topics_, t).b);
  Group(kSchema, group);
  group = out_.b.size();
  for (size_t t = 0; t < topics_.size(); ++t) out_.Raw(ChannelRecord(topics_, t).b);
  Group(kChannel, group);
  for (const auto& [channel, count] : counts) counts_map.U16(channel).U64(count);
  statistics.U64(messages.size()).U16(topics_.size()).U32(topics_.size()).U32(0).U32(0);
  statistics.U32(chunk_indexes_.size()).U64(messages.empty() ? 0 : start).U64(end);
  statistics.U32(counts_map.b.size()).Raw(counts_map.b);
  group = out_.b.size();
  out_.Record(kStatistics, statistics);
  Group(kStatistics, group);
  group = out_.b.size();
  for (const ChunkIndexEntry& e : chunk_indexes_) {
    Bytes offsets, content;
    for (const auto& [channel, offset] : e.index_offsets) offsets.U16(channel).U64(offset);
    content.U64(e.start).U64(e.end).U64(e.offset).U64(e.length).U32(offsets.b.size()).Raw(offsets.b);
    content.U64(e.index_length).String(options_.compression).U64(e.stored).U64(e.uncompressed);
    out_.Record(kChunkIndex, content);
  }
  if (!chunk_indexes_.empty()) Group(kChunkIndex, group);
}

McapTestFile Writer::Finish(const std::vector<BagMessage>& messages) {
  file_.data_end_offset = out_.b.size();
  out_.Record(kDataEnd, Bytes().U32(0));
  uint64_t summary_start = 0, summary_offset_start = 0;
  if (options_.summary) {
    summary_start = out_.b.size();
    Summary(messages);
    summary_offset_start = out_.b.size();
    for (size_t at = 0; at < groups_.b.size(); at += 17) {
      Bytes record;
      record.b.assign(groups_.b.begin() + at, groups_.b.begin() + at + 17);
      out_.Record(kSummaryOffset, record);
    }
  }
  out_.Record(kFooter, Bytes().U64(summary_start).U64(summary_offset_start).U32(0));
  out_.Raw(kMagic);
  file_.bytes = std::move(out_.b);
  return std::move(file_);
}

}  // namespace

McapTestFile WriteMcap(const std::vector<BagTopic>& topics, const std::vector<BagMessage>& messages,
                       const McapWriteOptions& options) {
  Writer writer(topics, options);
  if (!options.chunked) {
    writer.Unchunked(messages);
  } else {
    const size_t per_chunk = std::max<size_t>(1, options.messages_per_chunk);
    for (size_t first = 0; first < messages.size(); first += per_chunk)
      writer.Chunk(messages, first, std::min(per_chunk, messages.size() - first));
  }
  return writer.Finish(messages);
}

void WriteBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + path);
}

std::vector<uint8_t> ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

}  // namespace fusecal::testing
