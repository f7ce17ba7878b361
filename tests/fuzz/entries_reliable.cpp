// Fuzz entry of udpm://'s reliable layer (runtime/reliable/): the bytes are a sequence of datagrams as
// one bus receives them, each record [u8 kind][u16 length, little-endian][bytes]. kind bit 0: a control
// message (FUSECAL_RELIABLE) or a fragment; bit 1: on channel DATA or DATA2; bits 2-7: milliseconds
// that pass before it. Fed to one receiver and one publisher (sender 7, with a few messages of its own
// on DATA) as LcmBus does, with the receiver polled after every record: the state machine of NACKs,
// SKIPs, heartbeats and reassembly under hostile input.
#include <cstring>
#include <string>
#include <vector>

#include "fuzz_entries.hpp"
#include "fuzz_support.hpp"
#include "runtime/reliable/receiver.hpp"
#include "runtime/reliable/sender.hpp"
#include "runtime/reliable/wire.hpp"

namespace fusecal::fuzz {

using namespace fusecal::reliable;

int FuzzOneReliableUdpm(const uint8_t* data, size_t size) {
  int64_t now = 1000000;
  ReliableReceiver receiver(ReceiverOptions{20000, 50000, 200000}, now, [](const std::string& c) { return c.rfind("DATA", 0) == 0; });
  ReliableSender sender(7, SenderOptions{100, 2000, 1000});
  const std::vector<uint8_t> own(250, 3);
  for (int m = 0; m < 3; ++m) sender.Publish("DATA", own.data(), own.size(), now + m);
  size_t at = 0;
  while (size - at >= 3) {
    const uint8_t kind = data[at];
    uint16_t length = 0;
    std::memcpy(&length, data + at + 1, 2);
    at += 3;
    length = static_cast<uint16_t>(std::min<size_t>(length, size - at));
    const uint8_t* bytes = data + at;
    at += length;
    now += int64_t(kind >> 2) * 1000;
    const std::string channel = (kind & 2) ? "DATA2" : "DATA";
    IgnoringRejection([&] {
      if (kind & 1) {
        const Control control = DecodeControl(bytes, length);
        if (control.nack) sender.OnNack(*control.nack, now);
        if (control.heartbeat) receiver.OnHeartbeat(*control.heartbeat, now);
        if (control.skip) receiver.OnSkip(*control.skip, now);
      } else if (const auto header = DecodeFragmentHeader(bytes, length)) {
        receiver.OnFragment(channel, *header, bytes + kFragmentHeaderBytes, length - kFragmentHeaderBytes, now);
      }
    });
    receiver.Poll(now);
  }
  sender.MakeHeartbeat();
  return 0;
}

}  // namespace fusecal::fuzz
