// Deterministic random numbers for the simulator. Every frame, row and stream derives its own seed with
// MixSeed, so outputs do not depend on thread scheduling or on the order frames are requested in. The
// generators and distributions are written out here (not std:: distributions, whose results differ
// between standard libraries), so a seed gives the same bytes everywhere.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

namespace fusecal::sim {

// SplitMix64 finaliser: a well-mixed 64-bit hash.
inline uint64_t SplitMix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Seed of a sub-stream b of stream a (e.g. MixSeed(frame_seed, row)).
inline uint64_t MixSeed(uint64_t a, uint64_t b) { return SplitMix64(a ^ SplitMix64(b + 0x632BE59BD9B4E019ull)); }

// xoshiro256** (Blackman and Vigna), seeded through SplitMix64.
class Rng {
 public:
  explicit Rng(uint64_t seed) : table_(GaussianTable()) {
    for (auto& word : s_) word = seed = SplitMix64(seed);
  }

  uint64_t Next() {
    const uint64_t result = Rotl(s_[1] * 5, 7) * 9;
    const uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = Rotl(s_[3], 45);
    return result;
  }

  // Uniform in [0, 1).
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }

  // Standard normal (Box-Muller, one value per call).
  double Gaussian() {
    const double u1 = 1.0 - Uniform();  // (0, 1]
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

  // Standard normal quantised to 65536 levels (bounded by +-4.17), four per Next(): for the millions of
  // noise samples of every image and scan.
  float FastGaussian() {
    if (pending_ == 0) {
      bits_ = Next();
      pending_ = 4;
    }
    const float z = table_[bits_ & 0xFFFF];
    bits_ >>= 16;
    --pending_;
    return z;
  }

  // Inverse normal CDF at (i + 0.5) / 65536, i = 0..65535.
  static const float* GaussianTable();

 private:
  static uint64_t Rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  const float* table_;
  uint64_t s_[4];
  uint64_t bits_ = 0;
  int pending_ = 0;
};

inline const float* Rng::GaussianTable() {
  static const std::vector<float> table = [] {
    std::vector<float> t(65536);
    for (int i = 0; i < 65536; ++i) {
      const double p = (i + 0.5) / 65536.0;
      // Bisection on the normal CDF 0.5 erfc(-z / sqrt 2): exact to double precision, deterministic.
      double lo = -10.0, hi = 10.0;
      for (int k = 0; k < 60; ++k) {
        const double mid = 0.5 * (lo + hi);
        (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
      }
      t[i] = static_cast<float>(0.5 * (lo + hi));
    }
    return t;
  }();
  return table.data();
}

}  // namespace fusecal::sim
