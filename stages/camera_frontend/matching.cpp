#include "stages/camera_frontend/matching.hpp"

#include <cstdint>
#include <cstring>
#include <limits>

namespace fusecal::camera_frontend {

namespace {

// Descriptors copied into rows of whole 64-bit words (zero padded).
struct PackedDescriptors {
  int rows = 0;
  int words = 0;
  std::vector<std::uint64_t> data;
  const std::uint64_t* row(int r) const { return data.data() + static_cast<size_t>(r) * words; }
};

PackedDescriptors Pack(const cv::Mat& d) {
  PackedDescriptors p;
  p.rows = d.rows;
  p.words = static_cast<int>((d.cols + 7) / 8);
  p.data.assign(static_cast<size_t>(p.rows) * p.words, 0);
  for (int r = 0; r < d.rows; ++r) std::memcpy(p.data.data() + static_cast<size_t>(r) * p.words, d.ptr(r), d.cols);
  return p;
}

struct Nearest {
  int best = std::numeric_limits<int>::max();
  int second = std::numeric_limits<int>::max();
  int best_index = -1;
};

// One pass over all pairs: the two nearest j for every i, the nearest i for every j. Always inlined, so that
// __builtin_popcountll compiles to the popcnt instruction inside the function with target("popcnt").
__attribute__((always_inline)) inline void AllPairs(const PackedDescriptors& a, const PackedDescriptors& b,
                                                    std::vector<Nearest>* forward, std::vector<Nearest>* backward) {
  for (int i = 0; i < a.rows; ++i) {
    const std::uint64_t* x = a.row(i);
    Nearest& f = (*forward)[i];
    for (int j = 0; j < b.rows; ++j) {
      const std::uint64_t* y = b.row(j);
      int d = 0;
      for (int w = 0; w < a.words; ++w) d += __builtin_popcountll(x[w] ^ y[w]);
      if (d < f.best) {
        f.second = f.best;
        f.best = d;
        f.best_index = j;
      } else if (d < f.second) {
        f.second = d;
      }
      Nearest& g = (*backward)[j];
      if (d < g.best) {
        g.best = d;
        g.best_index = i;
      }
    }
  }
}

void AllPairsGeneric(const PackedDescriptors& a, const PackedDescriptors& b, std::vector<Nearest>* forward,
                     std::vector<Nearest>* backward) {
  AllPairs(a, b, forward, backward);
}

#if defined(__GNUC__) && defined(__x86_64__)
#define FUSECAL_HAVE_POPCNT_DISPATCH 1
__attribute__((target("popcnt"))) void AllPairsPopcnt(const PackedDescriptors& a, const PackedDescriptors& b,
                                                      std::vector<Nearest>* forward, std::vector<Nearest>* backward) {
  AllPairs(a, b, forward, backward);
}
#endif

}  // namespace

std::vector<cv::DMatch> MatchDescriptors(const cv::Mat& descriptors_i, const cv::Mat& descriptors_j,
                                         const MatchingSettings& settings) {
  std::vector<cv::DMatch> out;
  if (descriptors_i.rows < 1 || descriptors_j.rows < 2 || descriptors_i.cols != descriptors_j.cols ||
      descriptors_i.type() != CV_8U || descriptors_j.type() != CV_8U)
    return out;
  const PackedDescriptors a = Pack(descriptors_i), b = Pack(descriptors_j);
  std::vector<Nearest> forward(a.rows), backward(b.rows);
#ifdef FUSECAL_HAVE_POPCNT_DISPATCH
  if (__builtin_cpu_supports("popcnt"))
    AllPairsPopcnt(a, b, &forward, &backward);
  else
    AllPairsGeneric(a, b, &forward, &backward);
#else
  AllPairsGeneric(a, b, &forward, &backward);
#endif
  for (int i = 0; i < a.rows; ++i) {
    const Nearest& f = forward[i];
    if (f.best_index < 0 || !(f.best < settings.ratio * f.second)) continue;
    if (settings.mutual_check && backward[f.best_index].best_index != i) continue;
    out.emplace_back(i, f.best_index, static_cast<float>(f.best));
  }
  return out;
}

}  // namespace fusecal::camera_frontend
