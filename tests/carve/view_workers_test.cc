#include "carve/view_workers.h"

#include <algorithm>
#include <chrono>
#include <numeric>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace raycarve {
namespace {

TEST(ViewWorkers, ViewsAreDealtOutSoThatEveryViewIsInExactlyOneNonEmptyGroup) {
  for (int views : {1, 2, 3, 14, 48}) {
    for (int threads : {1, 2, 3, 5, 64}) {
      const ViewWorkers workers(views, threads);
      EXPECT_EQ(workers.num_groups(), std::min(views, threads));
      std::vector<int> seen(views, 0);
      for (int group = 0; group < workers.num_groups(); ++group) {
        const std::vector<int> mine = workers.ViewsOf(group);
        ASSERT_FALSE(mine.empty());
        EXPECT_TRUE(std::is_sorted(mine.begin(), mine.end()));
        for (int view : mine) {
          ++seen[view];
          EXPECT_EQ(workers.GroupOf(view), group);
        }
      }
      EXPECT_EQ(seen, std::vector<int>(views, 1));
    }
  }
  EXPECT_EQ(ViewWorkers(14, 2).ViewsOf(1), (std::vector<int>{1, 3, 5, 7, 9, 11, 13}));
  EXPECT_GE(ViewWorkers(16, 0).num_groups(), 1);  // one per hardware thread
}

TEST(ViewWorkers, EveryRunCallsEachGroupOnceAndReturnsAfterAllFinished) {
  ViewWorkers workers(14, 3);
  ASSERT_EQ(workers.num_groups(), 3);
  std::vector<int64_t> sums(3, 0);
  std::vector<int> calls(3, 0);
  int64_t expected = 0;
  for (int run = 1; run <= 20000; ++run) {
    auto task = [&](int group) {
      // Each group writes only its own slot; the caller reads them all after Run.
      sums[group] += run * (group + 1);
      ++calls[group];
    };
    workers.Run(task);
    expected += run;
    ASSERT_EQ(sums[0], expected);
    ASSERT_EQ(sums[1], 2 * expected);
    ASSERT_EQ(sums[2], 3 * expected);
  }
  EXPECT_EQ(calls, std::vector<int>(3, 20000));
}

TEST(ViewWorkers, WorkersThatFellAsleepWakeForTheNextRun) {
  ViewWorkers workers(4, 2);
  std::vector<int> calls(2, 0);
  for (int run = 0; run < 5; ++run) {
    // Longer than the workers spin: they sleep on the condition variable between runs.
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    auto task = [&](int group) {
      // A slower worker group: the caller gives up spinning and sleeps until it is done. (The
      // caller works too, twice as long as it waits: runs the workers did not hold up.)
      std::this_thread::sleep_for(std::chrono::milliseconds(group == 1 ? 6 : 4));
      ++calls[group];
    };
    workers.Run(task);
    EXPECT_EQ(calls[1], run + 1);
  }
  EXPECT_EQ(calls, std::vector<int>(2, 5));
  EXPECT_EQ(workers.times().inline_runs, 0);
}

TEST(ViewWorkers, TheTimesSayHowLongEachGroupWorkedAndHowLongTheRunsTook) {
  ViewWorkers workers(4, 2);
  ASSERT_EQ(workers.num_groups(), 2);
  for (int run = 0; run < 3; ++run) {
    // Group 1 works 10 ms a run, group 0 nothing: the caller (group 0) waits for it.
    auto task = [](int group) {
      if (group == 1) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    };
    workers.Run(task);
  }
  const ViewWorkers::Times times = workers.times();
  EXPECT_EQ(times.runs, 3);
  ASSERT_EQ(times.busy_seconds.size(), 2u);
  EXPECT_GE(times.busy_seconds[1], 0.030);
  EXPECT_LT(times.busy_seconds[0], 0.015);
  // The runs lasted as long as the slower group worked, at least.
  EXPECT_GE(times.wall_seconds, times.busy_seconds[1]);
  EXPECT_LE(times.busy_seconds[1], times.wall_seconds);
}

TEST(ViewWorkers, WorkersThatHoldUpTheRunsAreLeftForTheCallingThread) {
  // Group 1 takes 2 ms a run and group 0 nothing: every run waits on the worker, as when a busy
  // process beside takes its core. After a few such runs the calling thread runs both groups.
  ViewWorkers workers(4, 2);
  const std::thread::id caller = std::this_thread::get_id();
  int group1_on_caller = 0;
  for (int run = 0; run < 12; ++run) {
    auto task = [&](int group) {
      if (group != 1) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      if (std::this_thread::get_id() == caller) ++group1_on_caller;
    };
    workers.Run(task);
  }
  const ViewWorkers::Times times = workers.times();
  EXPECT_EQ(times.runs, 12);
  EXPECT_EQ(times.fallbacks, 1);
  // Four runs held up, then the rest on the calling thread.
  EXPECT_EQ(times.inline_runs, 8);
  EXPECT_EQ(group1_on_caller, 8);
}

}  // namespace
}  // namespace raycarve
