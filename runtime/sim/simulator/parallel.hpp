// A small parallel for: tasks 0..n-1 are handed out in chunks to `threads` workers (the caller is one of
// them). Each task must write only its own outputs, so results never depend on the scheduling.
// Plain std::thread workers that block when done (OpenMP's spinning workers slow everything down on a
// machine whose cores are shared with other jobs).
#pragma once

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace fusecal::sim {

// threads <= 0: one per hardware thread.
inline int ResolveThreads(int threads) {
  if (threads > 0) return threads;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

// Calls body(worker, task) for every task; worker in [0, threads) identifies per-worker scratch space.
template <typename Body>
void ParallelFor(int n, int threads, int chunk, const Body& body) {
  const int workers = std::min(ResolveThreads(threads), (n + chunk - 1) / std::max(1, chunk));
  if (workers <= 1) {
    for (int i = 0; i < n; ++i) body(0, i);
    return;
  }
  std::atomic<int> next{0};
  auto work = [&](int worker) {
    for (int begin; (begin = next.fetch_add(chunk)) < n;)
      for (int i = begin; i < std::min(n, begin + chunk); ++i) body(worker, i);
  };
  std::vector<std::thread> pool;
  for (int w = 1; w < workers; ++w) pool.emplace_back(work, w);
  work(0);
  for (auto& t : pool) t.join();
}

}  // namespace fusecal::sim
