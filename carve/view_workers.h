#pragma once

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

namespace raycarve {

// Fork-join for carving on several cores: one thread per group (the calling thread takes group
// 0), and Run(task) calls task(group) for every group at once and returns when all have
// finished. Two ways of sharing the work use it:
// - by view: the views are dealt out to groups like cards (view v to group v mod G). Dealing
//   rather than cutting into halves matters: neighbouring views see the same voxels, so with
//   halves a voxel seen from one side would load one thread only. (Set-up, and carving one voxel
//   at a time: a few microseconds of work per hand-over.)
// - by claiming: the groups claim views or voxels of a batch one at a time, so that a slow one
//   holds up no one else; what each gives is kept per view or voxel, so that the result does not
//   depend on which group took it (batched carving, carver.h).
//
// Workers spin briefly for the next task before sleeping on a condition variable; an idle pool
// costs nothing.
//
// Fork-join this fine-grained only pays while every thread has a core. When the workers fall
// behind (more threads than cores, or other busy processes: measured, 4 threads on 2 cores
// made a carve 27x slower, and a busy loop beside a carve on 2 cores made two threads 1.3-2x
// slower than one), Run notices and for a while runs every group on the calling thread, then
// tries again: after a few runs in a window that waited on the workers longer than the calling
// thread alone would have taken (each waits for a worker's next time slice), or after two
// windows in a row in which the threads together worked too little of the runs' wall time to
// beat one thread (see Account).
// Which thread runs a group never changes what the task computes.
//
// Tasks for different groups must touch disjoint data (each group its own views' structures and
// its own output buffers). Run is called from one thread at a time.
class ViewWorkers {
 public:
  // `num_threads` < 1 means one per core this process may use. At most one group per view; with
  // one group no thread is started and Run calls the task directly.
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
    RunErased([](void* erased, int group) { (*static_cast<Task*>(erased))(group); }, &task);
  }

  // Where the time of the runs so far went, for projecting how the work scales: the wall time
  // spent inside Run (from its start until the last group finished) and, per group, the time its
  // thread spent working on tasks. A group's waiting is the wall time less its work.
  struct Times {
    int64_t runs = 0;
    int64_t inline_runs = 0;  // runs done on the calling thread alone (see above)
    int64_t fallbacks = 0;    // times the workers were left idle for a while
    double wall_seconds = 0.0;
    std::vector<double> busy_seconds;  // per group
  };
  Times times() const;

 private:
  void RunErased(void (*call)(void*, int), void* task);
  void WorkerLoop(int group);
  // After a run on the workers: the calling thread's own time and its wait for the others.
  void Account(int64_t own_nanoseconds, int64_t wait_nanoseconds);
  // Runs the next inline_period_ runs on the calling thread alone and starts a new window.
  void LeaveWorkers();

  int num_views_;
  int num_groups_;
  // Runs left to do on the calling thread alone (0: use the workers), and the current window's
  // tally of parallel runs.
  int inline_runs_left_ = 0;
  int inline_period_ = 0;  // the last such while, in runs (see LeaveWorkers)
  bool trying_ = false;    // the workers are back after a while without them, for a window
  int window_runs_ = 0;
  int64_t window_own_ = 0;
  int64_t window_wait_ = 0;
  int64_t window_busy_start_ = 0;  // the groups' busy time summed, before the window's runs
  int window_lost_ = 0;            // runs the workers held up (see Account)
  bool starved_before_ = false;    // the window before had too few threads busy
  int64_t fallbacks_ = 0;
  std::vector<std::thread> threads_;
  int64_t runs_ = 0;
  int64_t inline_total_ = 0;
  int64_t wall_nanoseconds_ = 0;
  // Per group, on a cache line of its own: written by the group's thread, read between runs.
  struct alignas(64) Busy {
    int64_t nanoseconds = 0;
  };
  std::vector<Busy> busy_;
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

// Asks for the cache lines of [data, data + bytes) for writing, ahead of writing them (x86's
// PREFETCHW where the processor has it; elsewhere the compiler's prefetch for writing). For
// buffers that one thread writes task after task and another reads between tasks (a view's hits,
// read by the judging thread): each line the other core has read costs the writer a round trip
// between the cores when it next writes it, one line after another as the stores come; asked
// for at once, the round trips overlap, and with the work done before the writing. A hint: it
// changes nothing that the program computes.
void PrefetchForWriting(const void* data, size_t bytes);
// Fetches the cache lines of [data, data + bytes) ahead of reading them: for what another thread
// wrote, read in short runs from many buffers at once (a run per view), which the processor's
// own prefetching does not see coming.
void PrefetchForReading(const void* data, size_t bytes);

// Threads a pool would use for `num_threads` (< 1: the cores this process may run on, from its
// CPU affinity where the system reports one, else the hardware's threads).
int ResolveNumThreads(int num_threads);

// Calls body(item, group) for items [0, count) on `workers`, each group claiming `chunk`
// consecutive items at a time (uneven items spread over the groups). In a batch, consecutive
// items are neighbouring voxels, whose rays are neighbouring pixels: claimed together, one
// thread's writes stay off the cache lines the other threads write.
template <typename Body>
void ClaimItems(ViewWorkers& workers, int count, int chunk, Body body) {
  std::atomic<int> next{0};
  auto task = [&](int group) {
    for (int first; (first = next.fetch_add(chunk, std::memory_order_relaxed)) < count;) {
      const int last = std::min(count, first + chunk);
      for (int item = first; item < last; ++item) body(item, group);
    }
  };
  workers.Run(task);
}

}  // namespace raycarve
