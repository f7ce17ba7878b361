#include "runtime/reliable/wire.hpp"

#include <cstring>
#include <stdexcept>

namespace fusecal::reliable {

namespace {

enum ControlKind : uint8_t { kNack = 1, kHeartbeat = 2, kSkip = 3 };

// Little-endian writer and bounds-checked reader of the control layouts.
class Writer {
 public:
  template <typename T>
  void Put(T value) {
    const size_t at = bytes_.size();
    bytes_.resize(at + sizeof(T));
    std::memcpy(bytes_.data() + at, &value, sizeof(T));
  }
  void PutString(const std::string& text) {
    if (text.size() > 0xffff) throw std::invalid_argument("channel name longer than 65535 bytes");
    Put<uint16_t>(static_cast<uint16_t>(text.size()));
    const size_t at = bytes_.size();
    bytes_.resize(at + text.size());
    if (!text.empty()) std::memcpy(bytes_.data() + at, text.data(), text.size());
  }
  std::vector<uint8_t> Take() { return std::move(bytes_); }

 private:
  std::vector<uint8_t> bytes_;
};

class Reader {
 public:
  Reader(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  template <typename T>
  T Get(const char* what) {
    Need(sizeof(T), what);
    T value;
    std::memcpy(&value, data_ + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  std::string GetString(const char* what) {
    const size_t length = Get<uint16_t>(what);
    Need(length, what);
    std::string text(reinterpret_cast<const char*>(data_ + at_), length);
    at_ += length;
    return text;
  }
  size_t left() const { return size_ - at_; }

 private:
  void Need(size_t bytes, const char* what) const {
    if (size_ - at_ < bytes) throw std::invalid_argument(std::string("reliable control message truncated in ") + what);
  }
  const uint8_t* data_;
  size_t size_;
  size_t at_ = 0;
};

Writer StartControl(ControlKind kind, uint64_t sender) {
  Writer w;
  w.Put<uint32_t>(kControlMagic);
  w.Put<uint8_t>(kind);
  w.Put<uint64_t>(sender);
  return w;
}

}  // namespace

std::vector<uint8_t> EncodeFragment(const FragmentHeader& h, const uint8_t* payload, size_t bytes) {
  std::vector<uint8_t> out(kFragmentHeaderBytes + bytes);
  uint8_t* p = out.data();
  const auto put = [&p](const auto& value) {
    std::memcpy(p, &value, sizeof(value));
    p += sizeof(value);
  };
  put(kFragmentMagic);
  put(h.sender);
  put(h.seq);
  put(h.publish_utime);
  put(h.message_bytes);
  put(h.index);
  put(h.count);
  if (bytes) std::memcpy(p, payload, bytes);
  return out;
}

std::optional<FragmentHeader> DecodeFragmentHeader(const uint8_t* data, size_t size) {
  uint32_t magic = 0;
  if (size < kFragmentHeaderBytes) return std::nullopt;
  std::memcpy(&magic, data, 4);
  if (magic != kFragmentMagic) return std::nullopt;
  Reader r(data + 4, size - 4);
  FragmentHeader h;
  h.sender = r.Get<uint64_t>("sender");
  h.seq = r.Get<uint64_t>("seq");
  h.publish_utime = r.Get<int64_t>("utime");
  h.message_bytes = r.Get<uint32_t>("message size");
  h.index = r.Get<uint32_t>("index");
  h.count = r.Get<uint32_t>("count");
  if (h.seq >= kMaxSeq) throw std::invalid_argument("reliable fragment number " + std::to_string(h.seq) + " out of range");
  if (h.count == 0 || h.index >= h.count)
    throw std::invalid_argument("reliable fragment " + std::to_string(h.index) + " of " + std::to_string(h.count));
  // A fragment holds at most one datagram: a message cannot be larger than its fragments can carry.
  if (uint64_t(h.count) * kMaxFragmentBytes < h.message_bytes || h.count > uint64_t(h.message_bytes) + 1)
    throw std::invalid_argument("reliable fragment says " + std::to_string(h.count) + " fragments carry " +
                                std::to_string(h.message_bytes) + " bytes");
  if (size - kFragmentHeaderBytes > h.message_bytes)
    throw std::invalid_argument("reliable fragment of " + std::to_string(size - kFragmentHeaderBytes) +
                                " bytes for a message of " + std::to_string(h.message_bytes));
  return h;
}

std::vector<uint8_t> Encode(const Nack& nack) {
  Writer w = StartControl(kNack, nack.sender);
  w.PutString(nack.channel);
  w.Put<int64_t>(nack.since_utime);
  w.Put<uint32_t>(static_cast<uint32_t>(nack.ranges.size()));
  for (const auto& [from, to] : nack.ranges) {
    w.Put<uint64_t>(from);
    w.Put<uint64_t>(to);
  }
  return w.Take();
}

std::vector<uint8_t> Encode(const Heartbeat& heartbeat) {
  Writer w = StartControl(kHeartbeat, heartbeat.sender);
  w.Put<uint32_t>(static_cast<uint32_t>(heartbeat.last_seq.size()));
  for (const auto& [channel, seq] : heartbeat.last_seq) {
    w.PutString(channel);
    w.Put<uint64_t>(seq);
  }
  return w.Take();
}

std::vector<uint8_t> Encode(const Skip& skip) {
  Writer w = StartControl(kSkip, skip.sender);
  w.PutString(skip.channel);
  w.Put<uint64_t>(skip.range.first);
  w.Put<uint64_t>(skip.range.second);
  w.Put<int64_t>(skip.since_utime);
  return w.Take();
}

Control DecodeControl(const uint8_t* data, size_t size) {
  Reader r(data, size);
  if (r.Get<uint32_t>("magic") != kControlMagic) throw std::invalid_argument("not a reliable control message (magic)");
  const auto kind = r.Get<uint8_t>("kind");
  const auto sender = r.Get<uint64_t>("sender");
  Control control;
  if (kind == kNack) {
    Nack nack{sender, r.GetString("channel"), r.Get<int64_t>("since"), {}};
    const uint32_t count = r.Get<uint32_t>("range count");
    if (count > r.left() / 16) throw std::invalid_argument("reliable NACK declares more ranges than it holds");
    for (uint32_t k = 0; k < count; ++k) {
      const auto from = r.Get<uint64_t>("range");
      const auto to = r.Get<uint64_t>("range");
      if (to < from || to >= kMaxSeq) throw std::invalid_argument("reliable NACK range out of order or range");
      nack.ranges.emplace_back(from, to);
    }
    control.nack = std::move(nack);
  } else if (kind == kHeartbeat) {
    Heartbeat heartbeat{sender, {}};
    const uint32_t count = r.Get<uint32_t>("entry count");
    if (count > r.left() / 10) throw std::invalid_argument("reliable HEARTBEAT declares more entries than it holds");
    for (uint32_t k = 0; k < count; ++k) {
      std::string channel = r.GetString("channel");
      const auto seq = r.Get<uint64_t>("seq");
      if (seq >= kMaxSeq) throw std::invalid_argument("reliable HEARTBEAT number out of range");
      heartbeat.last_seq.emplace_back(std::move(channel), seq);
    }
    control.heartbeat = std::move(heartbeat);
  } else if (kind == kSkip) {
    Skip skip{sender, r.GetString("channel"), {}, 0};
    skip.range.first = r.Get<uint64_t>("range");
    skip.range.second = r.Get<uint64_t>("range");
    skip.since_utime = r.Get<int64_t>("since");
    if (skip.range.second < skip.range.first || skip.range.second >= kMaxSeq)
      throw std::invalid_argument("reliable SKIP range out of order or range");
    control.skip = std::move(skip);
  } else {
    throw std::invalid_argument("reliable control message of unknown kind " + std::to_string(kind));
  }
  return control;
}

}  // namespace fusecal::reliable
