// Fuzz entry of the DDS envelope (fuzz_entries.hpp): the bytes are the serialized payload of one
// fusecal::lcm_message sample as it arrives in an RTPS DATA submessage: a 4-byte encapsulation header
// (CDR or XCDR2, big- or little-endian) and the CDR of the sample. Cyclone DDS checks it
// (dds_stream_normalize_data) and reads it (dds_stream_read) before DdsBus sees it; DdsBus then counts
// the writer's sequence gap and hands the LCM bytes to the handlers (here: the LCM decoder of every type).
#include <cstring>
#include <string>
#include <vector>

#include "dds/ddsi/ddsi_cdrstream.h"
#include "fusecal_bytes.h"
#include "fuzz_entries.hpp"
#include "fuzz_support.hpp"
#include "runtime/dds/dds_envelope.hpp"
#include "stages/formats/message_json.hpp"

namespace fusecal::fuzz {

namespace {

constexpr size_t kHeaderBytes = 4;

// The XCDR version of an encapsulation identifier (big-endian on the wire) that a final type may
// carry, 0 for any other; *little_endian says the byte order of the data.
uint32_t XcdrVersion(const uint8_t* header, bool* little_endian) {
  *little_endian = (header[1] & 1) != 0;
  if (header[0] != 0) return 0;
  if (header[1] == 0x00 || header[1] == 0x01) return 1;  // CDR_BE, CDR_LE
  if (header[1] == 0x06 || header[1] == 0x07) return 2;  // CDR2_BE, CDR2_LE
  return 0;
}

void HandleSample(const fusecal_lcm_message& sample) {
  dds::SequenceGaps gaps;
  gaps.Count(1, 1);
  gaps.Count(1, sample.seq_number);
  gaps.Count(1, static_cast<uint64_t>(sample.utime));
  const std::string channel = sample.channel ? sample.channel : "";
  dds::ChannelName(dds::TopicName(channel));
  dds::ChannelName(channel);  // as a topic name from discovery
  std::string error;
  IgnoringRejection([&] { DecodeToJson(sample.data._buffer, sample.data._length, false, &error); });
}

}  // namespace

int FuzzOneDdsEnvelope(const uint8_t* data, size_t size) {
  if (size < kHeaderBytes || size > (1u << 30)) return 0;
  bool little_endian = false;
  const uint32_t xcdr_version = XcdrVersion(data, &little_endian);
  if (xcdr_version == 0) return 0;  // Cyclone drops the sample
  // A copy: Cyclone normalises (byte-swaps) the received data in place. One byte more, so that an
  // empty payload still has an address (Cyclone's arguments must not be null).
  const uint32_t payload_size = static_cast<uint32_t>(size - kHeaderBytes);
  std::vector<char> payload(payload_size + 1, 0);
  std::memcpy(payload.data(), data + kHeaderBytes, payload_size);
  const uint32_t* ops = fusecal_lcm_message_desc.m_ops;
  uint32_t used = 0;
  const bool bswap = little_endian != (DDSRT_ENDIAN == DDSRT_LITTLE_ENDIAN);
  if (!dds_stream_normalize_data(payload.data(), &used, payload_size, bswap, xcdr_version, ops)) return 0;
  dds_istream_t stream;
  dds_istream_init(&stream, used, payload.data(), xcdr_version);
  fusecal_lcm_message sample;
  std::memset(&sample, 0, sizeof sample);
  dds_stream_read(&stream, reinterpret_cast<char*>(&sample), ops);
  HandleSample(sample);
  dds_stream_free_sample(&sample, ops);
  dds_istream_fini(&stream);
  return 0;
}

}  // namespace fusecal::fuzz
