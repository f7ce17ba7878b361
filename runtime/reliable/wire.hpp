// What the reliable layer of the LCM bus puts on the wire (the guarantee itself: docs/design.md, "What
// the bus guarantees"). Nothing here knows LCM: these are byte layouts and their checks.
//
// A message published on a reliable udpm:// bus travels as fragments of at most `fragment_bytes`, each
// its own LCM message on the message's channel, so that a lost datagram costs one fragment and not the
// whole image (LCM drops a message when any of its datagrams is lost: at 5% packet loss a 6 MB image
// of ~100 datagrams would almost never arrive whole). Fragments carry a sequence number per publisher
// and channel (a "stream"); receivers ask again for the numbers they miss (NACK) on one control
// channel, publishers answer by sending the fragment again or saying it is gone (SKIP), and announce
// the last number of each stream twice a second (HEARTBEAT) so that a lost last fragment is noticed.
//
// Layouts are little-endian (x86-64 and ARM64). A fragment starts with kFragmentMagic, which no LCM
// message starts with in practice (LCM messages start with their type's 64-bit fingerprint): messages
// without it (plain LCM publishers, lcm-logplayer) are delivered as they come, without the guarantee.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace fusecal::reliable {

// The channel of NACK, HEARTBEAT and SKIP; never delivered to subscribers.
inline constexpr const char* kControlChannel = "FUSECAL_RELIABLE";

inline constexpr uint32_t kFragmentMagic = 0x46524346;  // "FCRF"
inline constexpr uint32_t kControlMagic = 0x43524346;   // "FCRC"

struct FragmentHeader {
  uint64_t sender = 0;         // the publishing bus (random per bus)
  uint64_t seq = 0;            // fragment number in the stream (sender, channel), from 0
  int64_t publish_utime = 0;   // when the whole message was published (the same on all its fragments)
  uint32_t message_bytes = 0;  // size of the whole message
  uint32_t index = 0;          // this fragment's place in its message
  uint32_t count = 0;          // fragments of the message
};
inline constexpr size_t kFragmentHeaderBytes = 40;
inline constexpr size_t kMaxFragmentBytes = 65536;  // payload; fragment_kb= allows at most 63
// Sequence numbers stay below this (a stream would need 2^62 fragments), so that "last + 1" never
// wraps around; decoders reject larger ones.
inline constexpr uint64_t kMaxSeq = uint64_t(1) << 62;

// Header + payload slice as one buffer.
std::vector<uint8_t> EncodeFragment(const FragmentHeader& header, const uint8_t* payload, size_t bytes);

// The header and where the payload starts, or nullopt when `data` is not a fragment (no magic).
// Throws std::invalid_argument for a fragment whose header does not hold together (index >= count,
// payload larger than the message, zero count).
std::optional<FragmentHeader> DecodeFragmentHeader(const uint8_t* data, size_t size);

// Inclusive ranges of sequence numbers.
using SeqRange = std::pair<uint64_t, uint64_t>;

// "Send these again": addressed to one publisher's stream. `since_utime` 0: a gap the receiver saw
// (everything in the ranges was published while it listened); otherwise the receiver's first contact
// with the stream: only what was published at or after since_utime is wanted, the rest predates it.
struct Nack {
  uint64_t sender = 0;
  std::string channel;
  int64_t since_utime = 0;
  std::vector<SeqRange> ranges;
};

// A publisher's last sequence number per stream it has published on.
struct Heartbeat {
  uint64_t sender = 0;
  std::vector<std::pair<std::string, uint64_t>> last_seq;
};

// "These will not come": no longer in the publisher's history (lost: since_utime 0), or published
// before the first contact of the receiver that asked with this since_utime (nothing lost, and only
// that receiver may pass over them: another one may still get them sent again).
struct Skip {
  uint64_t sender = 0;
  std::string channel;
  SeqRange range;
  int64_t since_utime = 0;
  bool lost() const { return since_utime == 0; }
};

std::vector<uint8_t> Encode(const Nack& nack);
std::vector<uint8_t> Encode(const Heartbeat& heartbeat);
std::vector<uint8_t> Encode(const Skip& skip);

// One control message, decoded; throws std::invalid_argument naming what is wrong when the bytes do
// not hold one (truncated, unknown kind, more ranges than bytes).
struct Control {
  std::optional<Nack> nack;
  std::optional<Heartbeat> heartbeat;
  std::optional<Skip> skip;
};
Control DecodeControl(const uint8_t* data, size_t size);

}  // namespace fusecal::reliable
