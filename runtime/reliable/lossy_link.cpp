#include "runtime/reliable/lossy_link.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace fusecal::reliable {

namespace {

// LCM's largest datagram payload (a fragment of a long message).
constexpr size_t kDatagramBytes = 65000;

}  // namespace

LossyLink::LossyLink(double loss, int64_t jitter_us, uint64_t seed) : loss_(loss), jitter_us_(jitter_us), random_(seed) {
  if (!(loss >= 0 && loss < 1)) throw std::invalid_argument("loss must be in [0, 1), is " + std::to_string(loss));
  if (jitter_us < 0) throw std::invalid_argument("jitter must not be negative");
}

bool LossyLink::Survives(size_t message_bytes) {
  if (loss_ <= 0) return true;
  const double datagrams = std::max<double>(1.0, std::ceil(double(message_bytes) / kDatagramBytes));
  const bool survives = std::uniform_real_distribution<double>(0, 1)(random_) < std::pow(1 - loss_, datagrams);
  if (!survives) ++lost_;
  return survives;
}

int64_t LossyLink::DelayUs() {
  if (jitter_us_ <= 0) return 0;
  return std::uniform_int_distribution<int64_t>(0, jitter_us_)(random_);
}

}  // namespace fusecal::reliable
