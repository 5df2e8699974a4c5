#include "carve/view_workers.h"

#include <algorithm>
#include <chrono>

#if defined(__linux__)
#include <sched.h>
#endif

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#include <immintrin.h>
#endif

namespace raycarve {
namespace {

// Waiting for the other side: first spinning (a few microseconds: the serial work between two
// tasks of a carve), then yielding the core (when there are more threads than cores, the thread
// waited for may need it), then sleeping (an idle pool costs nothing).
constexpr int kSpins = 256;
constexpr int kYields = 64;
// Runs per judgement of the workers, and runs on the calling thread alone before trying again
// (doubled while tries fail, up to kMaxInlineRuns: see LeaveWorkers). A short first while: a
// hiccup of the machine can leave the workers for nothing.
constexpr int kWindowRuns = 256;
constexpr int kInlineRuns = 1024;
constexpr int kMaxInlineRuns = 128 * kInlineRuns;
// Account: threads busy on average below which (two windows in a row) the workers are left
// idle, and runs the workers held up in a window that leave them at once.
constexpr double kMinBusyThreads = 1.0;
constexpr int kMaxLostRuns = 4;

int64_t NowNanoseconds() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// One round of waiting; returns false when it is time to sleep.
inline bool KeepWaiting(int round) {
  if (round < kSpins) {
#if defined(__x86_64__) || defined(__i386__)
    _mm_pause();
#endif
    return true;
  }
  if (round < kSpins + kYields) {
    std::this_thread::yield();
    return true;
  }
  return false;
}

#if defined(__x86_64__) || defined(__i386__)
// PREFETCHW: on every AMD64 processor and Intel's since Broadwell (CPUID 0x80000001, ECX bit 8).
bool HasPrefetchForWriting() {
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  return __get_cpuid(0x80000001, &eax, &ebx, &ecx, &edx) != 0 && (ecx & bit_PRFCHW) != 0;
}

#endif

}  // namespace

void PrefetchForWriting(const void* data, size_t bytes) {
  const char* begin = static_cast<const char*>(data);
#if defined(__x86_64__) || defined(__i386__)
  static const bool supported = HasPrefetchForWriting();
  if (!supported) return;
  // In assembly: a compiler may drop a call whose only effect is a prefetch.
  for (size_t offset = 0; offset < bytes; offset += 64) {
    asm volatile("prefetchw %0" : : "m"(*(begin + offset)));
  }
#else
  for (size_t offset = 0; offset < bytes; offset += 64) __builtin_prefetch(begin + offset, 1);
#endif
}

void PrefetchForReading(const void* data, size_t bytes) {
  const char* begin = static_cast<const char*>(data);
  for (size_t offset = 0; offset < bytes; offset += 64) {
#if defined(__x86_64__) || defined(__i386__)
    asm volatile("prefetcht0 %0" : : "m"(*(begin + offset)));  // as PrefetchForWriting
#else
    __builtin_prefetch(begin + offset);
#endif
  }
}

int ResolveNumThreads(int num_threads) {
  if (num_threads >= 1) return num_threads;
#if defined(__linux__)
  // A container or `taskset` may give the process fewer cores than the machine has.
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0 && CPU_COUNT(&set) > 0) return CPU_COUNT(&set);
#endif
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

ViewWorkers::ViewWorkers(int num_views, int num_threads)
    : num_views_(num_views),
      num_groups_(std::max(1, std::min(ResolveNumThreads(num_threads), num_views))),
      busy_(num_groups_) {
  for (int group = 1; group < num_groups_; ++group) {
    threads_.emplace_back([this, group] { WorkerLoop(group); });
  }
}

std::vector<int> ViewWorkers::ViewsOf(int group) const {
  std::vector<int> views;
  for (int view = group; view < num_views_; view += num_groups_) views.push_back(view);
  return views;
}

ViewWorkers::~ViewWorkers() {
  stop_.store(true);
  generation_.fetch_add(1);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    workers_wake_.notify_all();
  }
  for (std::thread& thread : threads_) thread.join();
}

ViewWorkers::Times ViewWorkers::times() const {
  Times times;
  times.runs = runs_;
  times.inline_runs = inline_total_;
  times.fallbacks = fallbacks_;
  times.wall_seconds = 1e-9 * static_cast<double>(wall_nanoseconds_);
  for (const Busy& busy : busy_) times.busy_seconds.push_back(1e-9 * busy.nanoseconds);
  return times;
}

void ViewWorkers::RunErased(void (*call)(void*, int), void* task) {
  ++runs_;
  if (num_groups_ == 1 || inline_runs_left_ > 0) {
    const int64_t start = NowNanoseconds();
    if (num_groups_ > 1) {
      --inline_runs_left_;
      ++inline_total_;
    }
    for (int group = 0; group < num_groups_; ++group) call(task, group);
    const int64_t elapsed = NowNanoseconds() - start;
    wall_nanoseconds_ += elapsed;
    busy_[0].nanoseconds += elapsed;
    return;
  }
  if (window_runs_ == 0) {
    window_busy_start_ = 0;
    for (const Busy& busy : busy_) window_busy_start_ += busy.nanoseconds;
  }
  const int64_t start = NowNanoseconds();
  call_ = call;
  task_ = task;
  pending_.store(num_groups_ - 1, std::memory_order_relaxed);
  generation_.fetch_add(1);  // sequentially consistent: publishes the task, then reads below
  if (sleeping_workers_.load() > 0) {
    std::lock_guard<std::mutex> lock(mutex_);
    workers_wake_.notify_all();
  }
  call(task, 0);
  const int64_t own_done = NowNanoseconds();
  for (int round = 0; pending_.load(std::memory_order_acquire) != 0; ++round) {
    if (KeepWaiting(round)) continue;
    std::unique_lock<std::mutex> lock(mutex_);
    caller_sleeping_.store(true);
    caller_wake_.wait(lock, [this] { return pending_.load() == 0; });
    caller_sleeping_.store(false);
    break;
  }
  const int64_t end = NowNanoseconds();
  wall_nanoseconds_ += end - start;
  busy_[0].nanoseconds += own_done - start;
  Account(own_done - start, end - own_done);
}

void ViewWorkers::Account(int64_t own_nanoseconds, int64_t wait_nanoseconds) {
  // On the calling thread alone a run would cost about num_groups x its own share; on the
  // workers it cost own + wait. A run that lost so (its workers held it up) is a hiccup when
  // alone; kMaxLostRuns in a window are a worker without a core: each such run waits for the
  // worker's next time slice (measured beside a busy loop on two cores: about a millisecond a
  // run, against 50-100 microseconds of work), so the workers are left at once.
  const bool lost = wait_nanoseconds > 2 * (num_groups_ - 1) * own_nanoseconds;
  window_lost_ += lost ? 1 : 0;
  window_own_ += own_nanoseconds;
  window_wait_ += wait_nanoseconds;
  if (window_lost_ >= kMaxLostRuns) {
    LeaveWorkers();
    return;
  }
  if (++window_runs_ < kWindowRuns) return;
  // Only a clear loss over the window counts (twice that).
  const bool losing = window_wait_ > 2 * (num_groups_ - 1) * window_own_;
  // The threads' work together against the runs' wall time: the threads busy on average. Below
  // one, the runs took longer than their work would on one thread (which does less work than
  // two: no cross-core traffic, README "Threads"). Measured on two quiet cores: 1.8-1.9, and
  // a single window below one in a few hundred (the machine's hiccups); beside a busy loop
  // 0.85-0.9 window after window. Two windows in a row count.
  int64_t busy = -window_busy_start_;
  for (const Busy& group_busy : busy_) busy += group_busy.nanoseconds;
  const int64_t wall = window_own_ + window_wait_;
  const bool starved = static_cast<double>(busy) < kMinBusyThreads * static_cast<double>(wall);
  if (losing || (starved && starved_before_)) {
    LeaveWorkers();
    return;
  }
  starved_before_ = starved;
  if (!starved) trying_ = false;
  window_runs_ = 0;
  window_own_ = 0;
  window_wait_ = 0;
  window_lost_ = 0;
}

void ViewWorkers::LeaveWorkers() {
  // Workers left again in the first window after a while without them: their cores are still
  // taken, and each try costs runs held up; try half as often, up to kMaxInlineRuns.
  inline_period_ = trying_ ? std::min(2 * inline_period_, kMaxInlineRuns) : kInlineRuns;
  inline_runs_left_ = inline_period_;
  trying_ = true;
  ++fallbacks_;
  starved_before_ = false;
  window_runs_ = 0;
  window_own_ = 0;
  window_wait_ = 0;
  window_lost_ = 0;
}

void ViewWorkers::WorkerLoop(int group) {
  uint64_t seen = 0;
  while (true) {
    uint64_t generation;
    for (int round = 0; (generation = generation_.load(std::memory_order_acquire)) == seen;
         ++round) {
      if (KeepWaiting(round)) continue;
      std::unique_lock<std::mutex> lock(mutex_);
      sleeping_workers_.fetch_add(1);
      workers_wake_.wait(lock, [this, seen] { return generation_.load() != seen; });
      sleeping_workers_.fetch_sub(1);
      round = 0;
    }
    seen = generation;
    if (stop_.load()) return;
    const int64_t start = NowNanoseconds();
    call_(task_, group);
    busy_[group].nanoseconds += NowNanoseconds() - start;
    if (pending_.fetch_sub(1) == 1 && caller_sleeping_.load()) {
      std::lock_guard<std::mutex> lock(mutex_);
      caller_wake_.notify_one();
    }
  }
}

}  // namespace raycarve
