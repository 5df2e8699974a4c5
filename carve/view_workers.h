#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

namespace raycarve {

// Fork-join over the views, for ray-cast carving on several cores. The views are dealt out to
// groups like cards (view v to group v mod G), one thread per group (the calling thread takes
// group 0), and Run(task) calls task(group) for every group at once and returns when all have
// finished. Dealing rather than cutting into halves matters: neighbouring views see the same
// voxels, so with halves a voxel seen from one side would load one thread only.
//
// Carving hands the workers a few microseconds of work per voxel, so they spin briefly for the
// next task before sleeping on a condition variable; an idle pool costs nothing.
//
// Fork-join this fine-grained only pays while every thread has a core. When the workers fall
// behind (more threads than cores, or other busy processes: measured, 4 threads on 2 cores
// made a carve 27x slower), Run notices that waiting for them costs more than their share of
// the work would, and for a while runs every group on the calling thread, then tries again.
// Which thread runs a group never changes what the task computes.
//
// Tasks for different groups must touch disjoint data (each group its own views' structures and
// its own output buffers). Run is called from one thread at a time.
class ViewWorkers {
 public:
  // `num_threads` < 1 means one per hardware thread. At most one group per view; with one
  // group no thread is started and Run calls the task directly.
  ViewWorkers(int num_views, int num_threads);
  ~ViewWorkers();
  ViewWorkers(const ViewWorkers&) = delete;
  ViewWorkers& operator=(const ViewWorkers&) = delete;

  int num_views() const { return num_views_; }
  int num_groups() const { return num_groups_; }
  int GroupOf(int view) const { return view % num_groups_; }
  // The views of `group`, in increasing order: group, group + G, group + 2G, ...
  std::vector<int> ViewsOf(int group) const;

  template <typename Task>
  void Run(Task& task) {
    if (num_groups_ == 1) {
      task(0);
      return;
    }
    RunErased([](void* erased, int group) { (*static_cast<Task*>(erased))(group); }, &task);
  }

 private:
  void RunErased(void (*call)(void*, int), void* task);
  void WorkerLoop(int group);
  // After a run on the workers: the calling thread's own time and its wait for the others.
  void Account(int64_t own_nanoseconds, int64_t wait_nanoseconds);

  int num_views_;
  int num_groups_;
  // Runs left to do on the calling thread alone (0: use the workers), and the current window's
  // tally of parallel runs.
  int inline_runs_left_ = 0;
  int window_runs_ = 0;
  int64_t window_own_ = 0;
  int64_t window_wait_ = 0;
  std::vector<std::thread> threads_;
  // The caller's and the workers' flags sit on cache lines of their own. The task being run is
  // written before generation_ is raised and read after it is seen.
  alignas(64) void (*call_)(void*, int) = nullptr;
  void* task_ = nullptr;
  std::atomic<uint64_t> generation_{0};
  alignas(64) std::atomic<int> pending_{0};  // groups of the current task still running on workers
  alignas(64) std::atomic<int> sleeping_workers_{0};
  std::atomic<bool> caller_sleeping_{false};
  std::atomic<bool> stop_{false};
  // Sleeping, after spinning: the flags say who sleeps, so that a wake-up costs a lock only then.
  std::mutex mutex_;
  std::condition_variable workers_wake_;
  std::condition_variable caller_wake_;
};

// Threads a pool would use for `num_threads` (< 1: the hardware's).
int ResolveNumThreads(int num_threads);

}  // namespace raycarve
