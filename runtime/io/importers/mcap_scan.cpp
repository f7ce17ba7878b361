// The linear pass over an MCAP data section (mcap_index.hpp). The summary is not read: a file cut short
// has none, and one that lies must not steer the reading.
#include <cstring>
#include <stdexcept>
#include <unordered_map>

#include "runtime/io/importers/mcap_fields.hpp"
#include "runtime/io/importers/mcap_index.hpp"
#include "runtime/io/importers/mcap_source.hpp"

namespace fusecal::mcap {

namespace {

constexpr uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr uint64_t kRecordHead = 9;       // opcode and uint64 length
constexpr uint64_t kFooterContent = 20;   // summary_start, summary_offset_start, summary_crc
constexpr uint64_t kMessageHead = 22;     // channel_id, sequence, log_time, publish_time
constexpr uint64_t kChunkFixedHead = 28;  // message_start/end_time, uncompressed_size, uncompressed_crc
enum Opcode : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kDataEnd = 0x0F
};
constexpr uint32_t kNoChannel = UINT32_MAX;

class Scanner {
 public:
  Scanner(ByteSource& source, const std::string& name, const Limits& limits)
      : source_(source), name_(name), limits_(limits) {}

  McapIndex Run() {
    CheckMagic();
    complete_ = EndsWithFooter();
    uint64_t offset = sizeof(kMagic);
    for (bool first = true;; first = false) {
      uint8_t op = 0;
      uint64_t length = 0;
      if (!RecordAt(offset, op, length)) break;
      if (first && op != kHeader) Fail("no Header record after the magic", offset);
      try {
        if (!ScanRecord(op, offset, length)) {
          // The data section is whole; only the summary, which is not needed, was cut.
          if (!complete_)
            index_.warnings.push_back(name_ +
                                      ": no footer (recording cut short after its data "
                                      "section); every message was read");
          break;
        }
      } catch (const McapError& e) {
        Fail(e.what(), offset);
      }
      offset += kRecordHead + length;
    }
    return std::move(index_);
  }

 private:
  [[noreturn]] void Fail(const std::string& what, uint64_t offset) const {
    throw std::runtime_error(name_ + ": " + what + " at offset " + std::to_string(offset));
  }

  void CheckMagic() {
    uint8_t magic[sizeof(kMagic)] = {};
    if (source_.size() < sizeof(kMagic)) Fail("not an MCAP file (shorter than the MCAP magic)", 0);
    source_.ReadAt(0, sizeof(kMagic), magic);
    if (std::memcmp(magic, kMagic, sizeof(kMagic)) != 0) Fail("not an MCAP file (no MCAP magic)", 0);
  }

  // A file that ends in a Footer record and the magic was closed by its writer: anything that does not
  // fit in it is an error. Without them the recording was cut short, and an incomplete last record is
  // what the cut left.
  bool EndsWithFooter() {
    const uint64_t tail = kRecordHead + kFooterContent + sizeof(kMagic);
    if (source_.size() < sizeof(kMagic) + tail) return false;
    const std::vector<uint8_t> bytes = source_.Read(source_.size() - tail, tail);
    return bytes[0] == kFooter && LoadLe(&bytes[1], 8) == kFooterContent &&
           std::memcmp(&bytes[kRecordHead + kFooterContent], kMagic, sizeof(kMagic)) == 0;
  }

  // Reads the opcode and length of the record at offset; false where the readable records end.
  bool RecordAt(uint64_t offset, uint8_t& op, uint64_t& length) {
    const uint64_t size = source_.size();
    if (size - offset < kRecordHead)
      return CutShort(offset, "an incomplete record header", "a record header runs past the end of the file");
    uint8_t head[kRecordHead];
    source_.ReadAt(offset, kRecordHead, head);
    op = head[0];
    length = LoadLe(head + 1, 8);
    if (op == 0) return CutShort(offset, "zero bytes where a record should start", "invalid opcode 0");
    // 64-bit arithmetic with no sum that can wrap: size - offset >= kRecordHead here.
    if (length > size - offset - kRecordHead)
      return CutShort(offset, "a record of " + std::to_string(length) + " bytes that the file does not hold",
                      "a record length of " + std::to_string(length) + " runs past the end of the file (" +
                          std::to_string(size) + " bytes)");
    return true;
  }

  // The end of what can be read: a warning in a file cut short, an error (`fault`) in one its writer closed.
  bool CutShort(uint64_t offset, const std::string& what, const std::string& fault) {
    if (complete_) Fail(fault, offset);
    const uint64_t dropped = source_.size() - offset;
    if (dropped == 0) {
      index_.warnings.push_back(name_ + ": no footer (recording cut short); every record up to the end at offset " +
                                std::to_string(offset) + " was read");
    } else {
      index_.warnings.push_back(name_ +
                                ": no footer (recording cut short); read to the last complete record, "
                                "which ends at offset " +
                                std::to_string(offset) + ", dropped " + std::to_string(dropped) + " bytes (" + what +
                                ")");
    }
    return false;
  }

  // Returns false at the end of the data section.
  bool ScanRecord(uint8_t op, uint64_t offset, uint64_t length) {
    const uint64_t content = offset + kRecordHead;
    switch (op) {
      case kSchema:
      case kChannel: {
        const std::vector<uint8_t> bytes = source_.Read(content, length);
        ScanDefinition(op, bytes.data(), length);
        return true;
      }
      case kMessage: {
        if (length < kMessageHead) throw McapError("Message record of " + std::to_string(length) + " bytes");
        const std::vector<uint8_t> head = source_.Read(content, kMessageHead);
        AddMessage(head.data(), length, kNoChunk, content + kMessageHead);
        return true;
      }
      case kChunk:
        ScanChunk(offset, length);
        return true;
      case kDataEnd:
      case kFooter:
        return false;
      default:  // Header, indexes, attachments, metadata, private records: not needed for the messages
        return true;
    }
  }

  void ScanDefinition(uint8_t op, const uint8_t* bytes, uint64_t length) {
    if (op == kSchema) {
      FieldReader fields(bytes, length, "Schema");
      const uint16_t id = fields.U16();
      std::string name = fields.String();
      std::string encoding = fields.String();
      if (id != 0) schemas_.emplace(id, std::make_pair(std::move(name), std::move(encoding)));
      return;
    }
    FieldReader fields(bytes, length, "Channel");
    Channel channel;
    channel.id = fields.U16();
    const uint16_t schema_id = fields.U16();
    channel.topic = fields.String();
    channel.message_encoding = fields.String();
    fields.SkipPrefixed();                         // metadata
    if (channel_by_id_.count(channel.id)) return;  // a repeat: the first definition stands
    if (schema_id != 0) {
      const auto schema = schemas_.find(schema_id);
      if (schema == schemas_.end())
        throw McapError("Channel " + std::to_string(channel.id) + " refers to schema " + std::to_string(schema_id) +
                        ", which no Schema record before it defines");
      channel.schema_name = schema->second.first;
      channel.schema_encoding = schema->second.second;
    }
    channel_by_id_[channel.id] = static_cast<uint32_t>(index_.channels.size());
    index_.channels.push_back(std::move(channel));
  }

  // head: the Message record's first kMessageHead bytes; data_offset: where its data starts.
  void AddMessage(const uint8_t* head, uint64_t length, uint32_t chunk, uint64_t data_offset) {
    const uint16_t channel_id = static_cast<uint16_t>(LoadLe(head, 2));
    const auto found = channel_by_id_.find(channel_id);
    const uint32_t channel = found == channel_by_id_.end() ? kNoChannel : found->second;
    if (channel == kNoChannel)
      throw McapError("Message on channel " + std::to_string(channel_id) +
                      ", which no Channel record before it defines");
    if (index_.messages.size() >= UINT32_MAX) throw McapError("more than 4294967295 messages in one file");
    MessageRef ref;
    ref.log_time_ns = static_cast<int64_t>(LoadLe(head + 6, 8));
    ref.offset = data_offset;
    ref.size = length - kMessageHead;
    ref.chunk = chunk;
    ref.channel = channel;
    index_.messages.push_back(ref);
    ++index_.channels[channel].message_count;
  }

  void ScanChunk(uint64_t offset, uint64_t length);
  void ScanChunkRecords(const std::vector<uint8_t>& records, uint32_t chunk);
  void ScanStoredRecords(uint64_t start, uint64_t size, uint32_t chunk);

  ByteSource& source_;
  const std::string& name_;
  Limits limits_;
  bool complete_ = false;
  McapIndex index_;
  // Index into index_.channels, by channel id (a map: a table of all 65536 ids cost more than a small
  // file took to read).
  std::unordered_map<uint16_t, uint32_t> channel_by_id_;
  std::unordered_map<uint16_t, std::pair<std::string, std::string>> schemas_;  // id: name, encoding
};

void Scanner::ScanChunk(uint64_t offset, uint64_t length) {
  const uint64_t content = offset + kRecordHead;
  if (length < kChunkFixedHead + 4 + 8) throw McapError("truncated chunk: " + std::to_string(length) + " bytes");
  const std::vector<uint8_t> head = source_.Read(content, kChunkFixedHead + 4);
  FieldReader fields(head.data(), head.size(), "Chunk");
  fields.Take(16);  // message start and end time: the messages carry their own
  const uint64_t uncompressed_size = fields.U64();
  const uint32_t crc = fields.U32();
  const uint64_t name_length = fields.U32();
  if (name_length > length - kChunkFixedHead - 4 - 8)
    throw McapError("truncated chunk: its compression name of " + std::to_string(name_length) +
                    " bytes runs past the record");
  const std::vector<uint8_t> rest = source_.Read(content + kChunkFixedHead + 4, name_length + 8);
  const std::string compression_name(reinterpret_cast<const char*>(rest.data()), name_length);
  const uint64_t stored_size = LoadLe(rest.data() + name_length, 8);
  const uint64_t head_size = kChunkFixedHead + 4 + name_length + 8;
  if (stored_size > length - head_size)
    throw McapError("truncated chunk: its records of " + std::to_string(stored_size) + " bytes run past the " +
                    std::to_string(length) + "-byte record");
  ChunkLocation location{offset, content + head_size, stored_size, uncompressed_size, Compression::kNone};
  if (!ParseCompression(compression_name, location.compression))
    throw McapError("unknown compression '" + compression_name + "' of a chunk");
  if (location.compression == Compression::kNone) {
    if (stored_size != uncompressed_size)
      throw McapError("uncompressed chunk of " + std::to_string(stored_size) +
                      " bytes declares an uncompressed size of " + std::to_string(uncompressed_size));
    if (uncompressed_size > limits_.max_chunk_bytes)
      throw McapError("chunk of " + std::to_string(uncompressed_size) + " uncompressed bytes exceeds the limit of " +
                      std::to_string(limits_.max_chunk_bytes));
    location.crc = crc;
    index_.chunks.push_back(location);
    ScanStoredRecords(location.stored_offset, stored_size, static_cast<uint32_t>(index_.chunks.size() - 1));
    return;
  }
  const std::vector<uint8_t> records =
      ChunkRecords(location.compression, source_.Read(location.stored_offset, stored_size), uncompressed_size,
                   limits_.max_chunk_bytes);
  const uint32_t actual_crc = crc == 0 ? 0 : Crc32(records.data(), records.size());
  if (actual_crc != crc)
    throw McapError("bad CRC of a chunk: its records have CRC32 " + std::to_string(actual_crc) + ", the chunk says " +
                    std::to_string(crc));
  index_.chunks.push_back(location);
  ScanChunkRecords(records, static_cast<uint32_t>(index_.chunks.size() - 1));
}

// The records of an uncompressed chunk, read in place: each record's header, a definition whole, a
// message's fixed head only (its data is read once, when it is visited).
void Scanner::ScanStoredRecords(uint64_t start, uint64_t size, uint32_t chunk) {
  uint8_t head[kRecordHead + kMessageHead];
  for (uint64_t at = 0; at < size;) {
    const auto where = [&] {
      return " at byte " + std::to_string(at) + " of the chunk's " + std::to_string(size) + " uncompressed bytes";
    };
    if (size - at < kRecordHead) throw McapError("chunk: an incomplete record header" + where());
    source_.ReadAt(start + at, kRecordHead, head);
    const uint8_t op = head[0];
    const uint64_t length = LoadLe(head + 1, 8);
    if (length > size - at - kRecordHead)
      throw McapError("chunk: a record length of " + std::to_string(length) + " runs past the records" + where());
    if (op == kSchema || op == kChannel) {
      const std::vector<uint8_t> content = source_.Read(start + at + kRecordHead, length);
      ScanDefinition(op, content.data(), length);
    } else if (op == kMessage) {
      if (length < kMessageHead)
        throw McapError("chunk: a Message record of " + std::to_string(length) + " bytes" + where());
      source_.ReadAt(start + at + kRecordHead, kMessageHead, head + kRecordHead);
      AddMessage(head + kRecordHead, length, chunk, at + kRecordHead + kMessageHead);
    }
    at += kRecordHead + length;
  }
}

// Schema, Channel and Message records inside a chunk; each length is checked against the records.
void Scanner::ScanChunkRecords(const std::vector<uint8_t>& records, uint32_t chunk) {
  const uint64_t size = records.size();
  for (uint64_t at = 0; at < size;) {
    const auto where = [&] {
      return " at byte " + std::to_string(at) + " of the chunk's " + std::to_string(size) + " uncompressed bytes";
    };
    if (size - at < kRecordHead) throw McapError("chunk: an incomplete record header" + where());
    const uint8_t op = records[at];
    const uint64_t length = LoadLe(&records[at + 1], 8);
    if (length > size - at - kRecordHead)
      throw McapError("chunk: a record length of " + std::to_string(length) + " runs past the records" + where());
    const uint8_t* content = &records[at + kRecordHead];
    if (op == kSchema || op == kChannel) {
      ScanDefinition(op, content, length);
    } else if (op == kMessage) {
      if (length < kMessageHead)
        throw McapError("chunk: a Message record of " + std::to_string(length) + " bytes" + where());
      AddMessage(content, length, chunk, at + kRecordHead + kMessageHead);
    }
    at += kRecordHead + length;
  }
}

}  // namespace

McapIndex ScanMcap(ByteSource& source, const std::string& name, const Limits& limits) {
  return Scanner(source, name, limits).Run();
}

}  // namespace fusecal::mcap
