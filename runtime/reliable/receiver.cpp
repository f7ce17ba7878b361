#include "runtime/reliable/receiver.hpp"

#include <algorithm>
#include <cstring>

namespace fusecal::reliable {

namespace {

constexpr size_t kMaxRangesPerNack = 64;

}  // namespace

ReliableReceiver::ReliableReceiver(ReceiverOptions options, int64_t subscribed_utime,
                                   std::function<bool(const std::string&)> matches)
    : options_(options), subscribed_utime_(subscribed_utime), matches_(std::move(matches)) {}

ReliableReceiver::Stream& ReliableReceiver::StreamFor(uint64_t sender, const std::string& channel, uint64_t seen_seq,
                                                      bool seen_is_fragment, int64_t now_utime) {
  auto [it, created] = streams_.try_emplace(Key{sender, channel});
  Stream& stream = it->second;
  if (!created) return stream;
  stream.channel = channel;
  stream.sender = sender;
  stream.last_heard = now_utime;
  // First contact: what came before `seen_seq` (and, from a HEARTBEAT, `seen_seq` itself) may have
  // been published after we subscribed and lost; it is asked for at the next Poll.
  const int64_t before = seen_is_fragment ? int64_t(seen_seq) - 1 : int64_t(seen_seq);
  if (before >= 0) {
    stream.contact_last = before;
    stream.known_last = uint64_t(before);
    stream.heard = true;
    stream.gap_since = now_utime - options_.nack_delay_us;
  }
  return stream;
}

std::vector<Delivery> ReliableReceiver::OnFragment(const std::string& channel, const FragmentHeader& header,
                                                   const uint8_t* payload, size_t bytes, int64_t now_utime) {
  Stream& stream = StreamFor(header.sender, channel, header.seq, true, now_utime);
  stream.last_heard = now_utime;
  if (header.seq < stream.next || stream.held.count(header.seq)) {
    ++duplicates_;
    return {};
  }
  stream.known_last = stream.heard ? std::max(stream.known_last, header.seq) : header.seq;
  stream.heard = true;
  stream.held.emplace(header.seq, Held{header, std::vector<uint8_t>(payload, payload + bytes), now_utime});
  return Drain(stream);
}

std::vector<Delivery> ReliableReceiver::OnSkip(const Skip& skip, int64_t /*now_utime*/) {
  auto it = streams_.find(Key{skip.sender, skip.channel});
  if (it == streams_.end()) return {};
  // A "before" SKIP answers one receiver's first contact; only that receiver may pass over it.
  if (!skip.lost() && skip.since_utime != subscribed_utime_) return {};
  Stream& stream = it->second;
  if (skip.range.second < stream.next) return {};
  const uint64_t from = std::max(skip.range.first, stream.next);
  stream.skips[from] = SkipRange{skip.range.second, skip.lost()};
  stream.known_last = std::max(stream.known_last, skip.range.second);
  stream.heard = true;
  return Drain(stream);
}

void ReliableReceiver::OnHeartbeat(const Heartbeat& heartbeat, int64_t now_utime) {
  for (const auto& [channel, last] : heartbeat.last_seq) {
    if (!matches_(channel)) continue;
    Stream& stream = StreamFor(heartbeat.sender, channel, last, false, now_utime);
    stream.last_heard = now_utime;
    if (!stream.heard || last > stream.known_last) stream.known_last = last;
    stream.heard = true;
  }
}

std::vector<Delivery> ReliableReceiver::Drain(Stream& stream) {
  std::vector<Delivery> out;
  for (;;) {
    auto skip = stream.skips.upper_bound(stream.next);
    if (skip != stream.skips.begin()) {
      --skip;
      if (skip->second.to >= stream.next) {
        if (skip->second.lost) ++lost_runs_;
        stream.count = 0;  // a message cut by the SKIP is not handed on
        stream.next = skip->second.to + 1;
        stream.held.erase(stream.held.begin(), stream.held.lower_bound(stream.next));
        stream.gap_since = 0;
        continue;
      }
    }
    auto held = stream.held.find(stream.next);
    if (held == stream.held.end()) break;
    Assemble(stream, held->second, &out);
    stream.held.erase(held);
    ++stream.next;
    stream.gap_since = 0;
  }
  while (!stream.skips.empty() && stream.skips.begin()->second.to < stream.next) stream.skips.erase(stream.skips.begin());
  return out;
}

void ReliableReceiver::Assemble(Stream& stream, Held& fragment, std::vector<Delivery>* out) {
  const FragmentHeader& h = fragment.header;
  if (h.index == 0) {
    // Grown fragment by fragment: the declared size is only believed once the bytes are there.
    stream.message.clear();
    stream.message.reserve(std::min<size_t>(h.message_bytes, kMaxFragmentBytes));
    stream.expected_bytes = h.message_bytes;
    stream.count = h.count;
    stream.expect_index = 0;
  } else if (stream.count == 0 || h.index != stream.expect_index || h.count != stream.count) {
    stream.count = 0;  // the rest of a message whose start was lost or predates our contact
    return;
  }
  if (stream.message.size() + fragment.payload.size() > stream.expected_bytes) {
    stream.count = 0;
    return;
  }
  stream.message.insert(stream.message.end(), fragment.payload.begin(), fragment.payload.end());
  if (++stream.expect_index < stream.count) return;
  stream.count = 0;
  if (stream.message.size() == stream.expected_bytes)
    out->push_back(Delivery{stream.channel, std::move(stream.message), fragment.receive_utime});
  stream.message.clear();
}

bool ReliableReceiver::HasGap(const Stream& stream) const { return stream.heard && stream.next <= stream.known_last; }

bool ReliableReceiver::has_gaps() const {
  for (const auto& [key, stream] : streams_)
    if (HasGap(stream)) return true;
  return false;
}

std::vector<SeqRange> ReliableReceiver::Missing(const Stream& stream, size_t max_ranges) const {
  std::vector<SeqRange> ranges;
  uint64_t cursor = stream.next;
  auto held = stream.held.lower_bound(cursor);
  auto skip = stream.skips.begin();
  while (cursor <= stream.known_last && ranges.size() < max_ranges) {
    while (skip != stream.skips.end() && skip->second.to < cursor) ++skip;
    while (held != stream.held.end() && held->first < cursor) ++held;
    uint64_t present = stream.known_last + 1, after = present;
    if (held != stream.held.end() && held->first < present) present = held->first, after = held->first + 1;
    if (skip != stream.skips.end() && std::max(skip->first, cursor) < present)
      present = std::max(skip->first, cursor), after = skip->second.to + 1;
    if (present > cursor) ranges.emplace_back(cursor, std::min(present - 1, stream.known_last));
    cursor = after;
  }
  return ranges;
}

void ReliableReceiver::GiveUp(Stream& stream) {
  ++lost_runs_;
  uint64_t resume = stream.known_last + 1;
  if (!stream.held.empty()) resume = std::min(resume, stream.held.begin()->first);
  if (!stream.skips.empty()) resume = std::min(resume, std::max(stream.skips.begin()->first, stream.next));
  stream.count = 0;
  stream.next = std::max(stream.next + 1, resume);
  stream.gap_since = 0;
}

ReliableReceiver::PollResult ReliableReceiver::Poll(int64_t now_utime) {
  PollResult result;
  for (auto& [key, stream] : streams_) {
    if (!HasGap(stream)) {
      stream.gap_since = 0;
      continue;
    }
    if (stream.gap_since == 0) stream.gap_since = now_utime;
    if (now_utime - stream.gap_since >= options_.give_up_us) {
      GiveUp(stream);
      auto delivered = Drain(stream);
      for (auto& d : delivered) result.deliveries.push_back(std::move(d));
      continue;
    }
    if (now_utime - stream.gap_since < options_.nack_delay_us || now_utime - stream.last_nack < options_.nack_retry_us)
      continue;
    stream.last_nack = now_utime;
    // Numbers up to contact_last are asked for as a first contact ("since subscribed"), later ones as a gap.
    Nack contact{stream.sender, stream.channel, subscribed_utime_, {}};
    Nack gap{stream.sender, stream.channel, 0, {}};
    for (const auto& [from, to] : Missing(stream, kMaxRangesPerNack)) {
      const int64_t split = stream.contact_last;
      if (int64_t(to) <= split) {
        contact.ranges.emplace_back(from, to);
      } else if (int64_t(from) > split) {
        gap.ranges.emplace_back(from, to);
      } else {
        contact.ranges.emplace_back(from, uint64_t(split));
        gap.ranges.emplace_back(uint64_t(split) + 1, to);
      }
    }
    if (!contact.ranges.empty()) result.nacks.push_back(std::move(contact));
    if (!gap.ranges.empty()) result.nacks.push_back(std::move(gap));
  }
  return result;
}

}  // namespace fusecal::reliable
