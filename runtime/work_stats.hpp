// What a stage reports about its work in STATUS: how many items it did (frames, station pairs, motions)
// and how long each took (mean, 95th percentile), and how many raw frames it skipped. `fusecal run`
// and `calibrate` write these per stage to stages.csv; tools/bench-realtime reads them.
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <string>
#include <vector>

namespace fusecal {

class WorkStats {
 public:
  void Add(double seconds) {
    total_s_ += seconds;
    ++items_;
    // Enough for the percentile of a session; beyond it every other sample is kept.
    if (samples_ms_.size() >= kMaxSamples) Thin();
    if (items_ % stride_ == 0) samples_ms_.push_back(seconds * 1e3);
  }
  void AddSkipped(long count = 1) { skipped_ += count; }

  long items() const { return items_; }
  long skipped() const { return skipped_; }
  double total_s() const { return total_s_; }
  double mean_ms() const { return items_ ? total_s_ * 1e3 / items_ : 0.0; }
  double p95_ms() const {
    if (samples_ms_.empty()) return 0.0;
    std::vector<double> v = samples_ms_;
    const size_t k = std::min(v.size() - 1, static_cast<size_t>(std::ceil(0.95 * v.size())) - 1);
    std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
    return v[k];
  }
  // STATUS counters: items, item_ms_mean, item_ms_p95, skipped, busy_s.
  void AddTo(std::map<std::string, double>* counters) const {
    (*counters)["items"] = static_cast<double>(items_);
    (*counters)["item_ms_mean"] = mean_ms();
    (*counters)["item_ms_p95"] = p95_ms();
    (*counters)["skipped"] = static_cast<double>(skipped_);
    (*counters)["busy_s"] = total_s_;
  }

  // Times one item: `WorkStats::Timer t(&stats);` adds the elapsed time when it goes out of scope.
  class Timer {
   public:
    explicit Timer(WorkStats* stats) : stats_(stats), start_(std::chrono::steady_clock::now()) {}
    ~Timer() { stats_->Add(std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count()); }
    Timer(const Timer&) = delete;
    Timer& operator=(const Timer&) = delete;

   private:
    WorkStats* stats_;
    std::chrono::steady_clock::time_point start_;
  };

 private:
  static constexpr size_t kMaxSamples = 20000;
  void Thin() {
    std::vector<double> kept;
    for (size_t k = 0; k < samples_ms_.size(); k += 2) kept.push_back(samples_ms_[k]);
    samples_ms_.swap(kept);
    stride_ *= 2;
  }
  long items_ = 0, skipped_ = 0;
  long stride_ = 1;
  double total_s_ = 0;
  std::vector<double> samples_ms_;
};

}  // namespace fusecal
