#pragma once

#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace raycarve {
namespace exporter {

// Runs body(begin, end) over [0, n) split into contiguous ranges, one per thread, at most
// `threads` and at least `min_per_thread` items each (fewer threads for less work). The ranges'
// results must not depend on each other, so the outcome is the same for any thread count.
template <typename Body>
void ParallelRanges(size_t n, int threads, size_t min_per_thread, const Body& body) {
  const size_t most = std::max<size_t>(1, n / std::max<size_t>(1, min_per_thread));
  const int count = static_cast<int>(std::max<size_t>(1, std::min<size_t>(std::max(threads, 1), most)));
  if (count == 1) {
    body(size_t{0}, n);
    return;
  }
  std::vector<std::thread> workers;
  for (int t = 0; t < count; ++t) {
    const size_t begin = n * t / count, end = n * (t + 1) / count;
    workers.emplace_back([&body, begin, end] { body(begin, end); });
  }
  for (std::thread& worker : workers) worker.join();
}

}  // namespace exporter
}  // namespace raycarve
