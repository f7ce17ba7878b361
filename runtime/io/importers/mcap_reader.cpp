#include "runtime/io/importers/mcap_reader.hpp"

#include <algorithm>
#include <stdexcept>

#include "runtime/io/importers/mcap_fields.hpp"
#include "runtime/io/importers/mcap_index.hpp"
#include "runtime/io/importers/mcap_source.hpp"

namespace fusecal::mcap {

McapReader::McapReader(const std::string& path, const Limits& limits)
    : McapReader(path, OpenFileSource(path), limits) {}

McapReader::McapReader(const std::string& name, std::unique_ptr<ByteSource> source, const Limits& limits)
    : name_(name),
      source_(std::move(source)),
      limits_(limits),
      index_(std::make_unique<McapIndex>(ScanMcap(*source_, name_, limits_))) {}

McapReader::~McapReader() = default;

const std::vector<Channel>& McapReader::channels() const { return index_->channels; }
const std::vector<std::string>& McapReader::warnings() const { return index_->warnings; }
uint64_t McapReader::bytes_read() const { return source_->bytes_read(); }

std::unique_ptr<McapCursor> McapReader::Messages(const std::vector<bool>& selected) {
  const std::vector<MessageRef>& messages = index_->messages;
  std::vector<uint32_t> order;
  order.reserve(messages.size());
  for (uint32_t i = 0; i < messages.size(); ++i)
    if (selected.empty() || (messages[i].channel < selected.size() && selected[messages[i].channel]))
      order.push_back(i);
  const auto earlier = [&](uint32_t a, uint32_t b) { return messages[a].log_time_ns < messages[b].log_time_ns; };
  // Recorders write in receive order, so the sort is usually already done.
  if (!std::is_sorted(order.begin(), order.end(), earlier)) std::stable_sort(order.begin(), order.end(), earlier);
  return std::unique_ptr<McapCursor>(new McapCursor(*this, std::move(order)));
}

std::unique_ptr<McapReader> ReadMcapFromMemory(const std::string& name, const uint8_t* data, size_t size,
                                               const Limits& limits) {
  return std::make_unique<McapReader>(name, MemorySource(data, size), limits);
}

McapCursor::McapCursor(McapReader& reader, std::vector<uint32_t> order)
    : reader_(reader),
      order_(std::move(order)),
      pending_(reader.index_->chunks.size(), 0),
      chunk_data_(reader.index_->chunks.size()) {
  for (const uint32_t i : order_) {
    const uint32_t chunk = reader_.index_->messages[i].chunk;
    if (chunk != kNoChunk) ++pending_[chunk];
  }
}

McapCursor::~McapCursor() = default;

// The previous message's data stayed valid until now; its chunk goes once no selected message needs it.
void McapCursor::ReleasePrevious() {
  if (!has_previous_) return;
  has_previous_ = false;
  const uint32_t chunk = reader_.index_->messages[order_[next_ - 1]].chunk;
  if (chunk != kNoChunk && --pending_[chunk] == 0) {
    spare_.swap(chunk_data_[chunk]);
    std::vector<uint8_t>().swap(chunk_data_[chunk]);
  }
}

const uint8_t* McapCursor::ChunkData(uint32_t chunk) {
  std::vector<uint8_t>& data = chunk_data_[chunk];
  if (!data.empty()) return data.data();
  const ChunkLocation& location = reader_.index_->chunks[chunk];
  std::vector<uint8_t> stored = std::move(spare_);
  spare_.clear();
  stored.resize(location.stored_size);
  reader_.source_->ReadAt(location.stored_offset, location.stored_size, stored.data());
  try {
    data = ChunkRecords(location.compression, std::move(stored), location.uncompressed_size,
                        reader_.limits_.max_chunk_bytes);
  } catch (const McapError& e) {
    // The scan read this chunk whole, so the file changed since.
    throw std::runtime_error(reader_.name_ + ": " + e.what() + " at offset " + std::to_string(location.record_offset) +
                             " (the chunk read well when the file was opened)");
  }
  if (location.compression == Compression::kNone && location.crc != 0) {
    const uint32_t actual = Crc32(data.data(), data.size());
    if (actual != location.crc)
      throw std::runtime_error(reader_.name_ + ": bad CRC of a chunk: its records have CRC32 " +
                               std::to_string(actual) + ", the chunk says " + std::to_string(location.crc) +
                               " at offset " + std::to_string(location.record_offset));
  }
  return data.data();
}

bool McapCursor::Next(Message& message) {
  ReleasePrevious();
  if (next_ == order_.size()) return false;
  const MessageRef& ref = reader_.index_->messages[order_[next_++]];
  has_previous_ = true;
  const uint8_t* data = nullptr;
  if (ref.chunk == kNoChunk) {
    loose_ = reader_.source_->Read(ref.offset, ref.size);
    data = loose_.data();
  } else {
    // Offsets were checked against the records by the scan, and ChunkRecords yields exactly that size.
    data = ChunkData(ref.chunk) + ref.offset;
  }
  message.channel = ref.channel;
  message.log_time_ns = ref.log_time_ns;
  message.data = data;
  message.size = static_cast<size_t>(ref.size);
  return true;
}

}  // namespace fusecal::mcap
