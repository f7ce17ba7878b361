// Loss and jitter put on what a bus receives (URL parameters loss= and jitter_ms=), to test the
// reliable layer where `tc netem` is not available (kernels without sch_netem). A message is lost when
// any of its datagrams is: LCM sends up to ~64 KB per datagram, and on loopback one datagram is one
// packet, so this is what netem's per-packet loss does to whole messages. Jitter holds each message
// back by a uniform 0..jitter, which reorders them as netem's delay with jitter does.
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>

namespace fusecal::reliable {

class LossyLink {
 public:
  // `loss`: probability that a datagram is lost, in [0, 1); `jitter_us` >= 0.
  LossyLink(double loss, int64_t jitter_us, uint64_t seed);

  bool active() const { return loss_ > 0 || jitter_us_ > 0; }
  bool Survives(size_t message_bytes);
  int64_t DelayUs();
  uint64_t lost() const { return lost_; }

 private:
  double loss_;
  int64_t jitter_us_;
  std::mt19937_64 random_;
  uint64_t lost_ = 0;
};

}  // namespace fusecal::reliable
