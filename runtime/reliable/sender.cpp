#include "runtime/reliable/sender.hpp"

#include <algorithm>
#include <stdexcept>

namespace fusecal::reliable {

namespace {

constexpr uint64_t kMaxFragmentsPerNack = 4096;

}  // namespace

ReliableSender::ReliableSender(uint64_t sender_id, SenderOptions options) : id_(sender_id), options_(options) {
  if (options_.fragment_bytes == 0) throw std::invalid_argument("reliable fragment size must be positive");
}

std::vector<Outgoing> ReliableSender::Publish(const std::string& channel, const uint8_t* data, size_t size,
                                              int64_t now_utime) {
  if (size > UINT32_MAX) throw std::invalid_argument("message of " + std::to_string(size) + " bytes exceeds 4 GB");
  Stream& stream = streams_[channel];
  const size_t count = std::max<size_t>(1, (size + options_.fragment_bytes - 1) / options_.fragment_bytes);
  std::vector<Outgoing> out;
  out.reserve(count);
  for (size_t index = 0; index < count; ++index) {
    const size_t begin = index * options_.fragment_bytes;
    const size_t bytes = std::min(options_.fragment_bytes, size - std::min(size, begin));
    FragmentHeader header{id_, stream.next_seq, now_utime, uint32_t(size), uint32_t(index), uint32_t(count)};
    std::vector<uint8_t> fragment = EncodeFragment(header, data + begin, bytes);
    out.push_back({channel, fragment});
    Keep(channel, stream.next_seq, Kept{std::move(fragment), now_utime, now_utime});
    ++stream.next_seq;
  }
  Evict();
  return out;
}

void ReliableSender::Keep(const std::string& channel, uint64_t seq, Kept kept) {
  history_bytes_ += kept.bytes.size();
  streams_[channel].kept.emplace(seq, std::move(kept));
  order_.emplace_back(channel, seq);
}

void ReliableSender::Evict() {
  while (history_bytes_ > options_.history_bytes && !order_.empty()) {
    const auto [channel, seq] = order_.front();
    Stream& stream = streams_[channel];
    if (seq + 1 == stream.next_seq) break;  // the newest of its stream answers a lost last fragment
    auto it = stream.kept.find(seq);
    if (it != stream.kept.end()) {
      history_bytes_ -= it->second.bytes.size();
      stream.kept.erase(it);
    }
    order_.pop_front();
  }
}

std::vector<Outgoing> ReliableSender::OnNack(const Nack& nack, int64_t now_utime) {
  std::vector<Outgoing> out;
  if (nack.sender != id_) return out;
  auto found = streams_.find(nack.channel);
  if (found == streams_.end() || found->second.next_seq == 0) return out;
  Stream& stream = found->second;
  const bool first_contact = nack.since_utime != 0;
  // SKIP ranges are merged as they are found, in order.
  std::vector<Skip> skips;
  // Not kept: lost for a gap, before the contact for a first contact (since_utime says which).
  const auto skip = [&](uint64_t seq) {
    if (!skips.empty() && skips.back().range.second + 1 == seq) {
      skips.back().range.second = seq;
      return;
    }
    skips.push_back(Skip{id_, nack.channel, {seq, seq}, nack.since_utime});
  };
  // Bounded work per NACK, whatever it asks for: the rest is asked for again.
  uint64_t budget = kMaxFragmentsPerNack;
  for (auto [from, to] : nack.ranges) {
    to = std::min(to, stream.next_seq - 1);
    if (from > to) continue;
    // Not kept: everything below the oldest kept fragment, in one range.
    const uint64_t oldest = stream.kept.empty() ? stream.next_seq : stream.kept.begin()->first;
    if (from < oldest) {
      const uint64_t end = std::min(to, oldest - 1);
      skips.push_back(Skip{id_, nack.channel, {from, end}, nack.since_utime});
      from = end + 1;
    }
    for (uint64_t seq = from; seq <= to && seq >= from && budget > 0; ++seq, --budget) {
      auto it = stream.kept.find(seq);
      if (it == stream.kept.end() || (first_contact && it->second.publish_utime < nack.since_utime)) {
        skip(seq);
      } else if (now_utime - it->second.last_sent_utime >= options_.resend_gap_us) {
        it->second.last_sent_utime = now_utime;
        out.push_back({nack.channel, it->second.bytes});
        ++resent_;
      }
    }
  }
  for (const auto& s : skips) out.push_back({kControlChannel, Encode(s)});
  return out;
}

std::vector<Outgoing> ReliableSender::MakeHeartbeat() const {
  Heartbeat heartbeat{id_, {}};
  for (const auto& [channel, stream] : streams_)
    if (stream.next_seq > 0) heartbeat.last_seq.emplace_back(channel, stream.next_seq - 1);
  if (heartbeat.last_seq.empty()) return {};
  return {{kControlChannel, Encode(heartbeat)}};
}

}  // namespace fusecal::reliable
