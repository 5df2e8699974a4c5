#include "export/parallel_ranges.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

namespace raycarve {
namespace exporter {
namespace {

// The ranges one call hands out, sorted by their start.
std::vector<std::pair<size_t, size_t>> RangesOf(size_t n, int threads, size_t min_per_thread) {
  std::mutex mutex;
  std::vector<std::pair<size_t, size_t>> ranges;
  ParallelRanges(n, threads, min_per_thread, [&](size_t begin, size_t end) {
    std::lock_guard<std::mutex> lock(mutex);
    ranges.emplace_back(begin, end);
  });
  std::sort(ranges.begin(), ranges.end());
  return ranges;
}

TEST(ParallelRanges, EveryItemOnceInContiguousRanges) {
  for (const size_t n : {size_t{0}, size_t{1}, size_t{7}, size_t{1000}, size_t{100003}}) {
    for (const int threads : {1, 2, 3, 8}) {
      for (const size_t min_per_thread : {size_t{1}, size_t{64}, size_t{4096}}) {
        const auto ranges = RangesOf(n, threads, min_per_thread);
        ASSERT_FALSE(ranges.empty());
        size_t next = 0;
        for (const auto& [begin, end] : ranges) {
          ASSERT_EQ(begin, next) << "n " << n << ", " << threads << " threads, min " << min_per_thread;
          ASSERT_LE(begin, end);
          next = end;
        }
        EXPECT_EQ(next, n) << "n " << n << ", " << threads << " threads, min " << min_per_thread;
      }
    }
  }
}

TEST(ParallelRanges, WorkIsHandedOutInPiecesSoThatUnevenWorkSpreads) {
  // One thread: the whole range at once.
  EXPECT_EQ(RangesOf(10000, 1, 64).size(), 1u);
  // Fewer items than two threads' minimum: one range.
  EXPECT_EQ(RangesOf(100, 2, 64).size(), 1u);
  // Two threads: pieces of min_per_thread items (the last one the rest).
  const auto pieces = RangesOf(10000, 2, 64);
  ASSERT_EQ(pieces.size(), (10000u + 63) / 64);
  for (size_t k = 0; k + 1 < pieces.size(); ++k) EXPECT_EQ(pieces[k].second - pieces[k].first, 64u);
  // Where min_per_thread items a piece would leave fewer than four pieces a thread, the pieces
  // shrink: 4 threads, 100 items, at least 16 pieces.
  const auto small = RangesOf(100, 4, 25);
  EXPECT_GE(small.size(), 16u);
  // Views (min 1): one at a time.
  EXPECT_EQ(RangesOf(12, 2, 1).size(), 12u);
}

TEST(ParallelRanges, TwoThreadsRunPiecesAtTheSameTime) {
  // Each piece waits (10 s at most in all) until another thread runs a piece too: on one thread
  // alone no piece would see a second one running.
  std::atomic<int> running{0}, seen_together{0};
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  ParallelRanges(8, 2, 1, [&](size_t, size_t) {
    running.fetch_add(1);
    while (running.load() < 2 && seen_together.load() == 0 &&
           std::chrono::steady_clock::now() < give_up) {
    }
    if (running.load() >= 2) seen_together.store(1);
    running.fetch_sub(1);
  });
  EXPECT_EQ(seen_together.load(), 1);
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
