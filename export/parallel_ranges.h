#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace raycarve {
namespace exporter {

// Runs body(begin, end) over [0, n) in contiguous ranges on at most `threads` threads, with at
// least `min_per_thread` items per thread (fewer threads for less work). The threads claim the
// ranges one at a time, in order, so that uneven work (vertices one photo sees and another not,
// photos of different sizes) spreads over them: each range holds min_per_thread items, or fewer
// where that would leave under four ranges a thread. The ranges' results must not depend on
// each other or on which thread ran them, so the outcome is the same for any thread count.
template <typename Body>
void ParallelRanges(size_t n, int threads, size_t min_per_thread, const Body& body) {
  const size_t most = std::max<size_t>(1, n / std::max<size_t>(1, min_per_thread));
  const int count = static_cast<int>(std::max<size_t>(1, std::min<size_t>(std::max(threads, 1), most)));
  if (count == 1) {
    body(size_t{0}, n);
    return;
  }
  const size_t chunk = std::max<size_t>(
      1, std::min<size_t>(min_per_thread, n / (static_cast<size_t>(count) * 4)));
  std::atomic<size_t> next{0};
  const auto work = [&] {
    for (;;) {
      const size_t begin = next.fetch_add(chunk, std::memory_order_relaxed);
      if (begin >= n) return;
      body(begin, std::min(n, begin + chunk));
    }
  };
  std::vector<std::thread> workers;
  for (int t = 1; t < count; ++t) workers.emplace_back(work);
  work();
  for (std::thread& worker : workers) worker.join();
}

}  // namespace exporter
}  // namespace raycarve
