#pragma once
// Internal to carve/: the incremental carver behind CarveVolume (carver.h), for carve/'s own files
// and its tests, which step it and look inside. Not for use outside carve/.

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <queue>
#include <vector>

#include "carve/carver.h"
#include "carve/ray_cast_visibility.h"
#include "carve/view_workers.h"
#include "carve/voxel_colour_sums.h"

namespace raycarve {

// The carving loop of the seed paper, one CVSVL entry at a time (CarveVolume runs it to the end;
// tests step it and look inside). The CVSVL is first in, first out, and holds a voxel at most
// once at a time; it starts as the whole surface. With GVC, whenever it runs empty after a pass
// that carved, the buffers are re-rendered and the whole surface is queued again.
class IncrementalCarver {
 public:
  // Makes the visibility over the carver's volume (which outlives it).
  using VisibilityFactory = std::function<std::unique_ptr<Visibility>(
      const std::vector<CalibratedView>& views, const Volume& volume)>;

  // `views` must outlive the carver. Options must pass CheckCarveFits (CHECKed). The visibility
  // is options.method's, or what `factory` makes (a method of one's own, or an instrumented one).
  IncrementalCarver(const std::vector<CalibratedView>& views,
                    const Eigen::AlignedBox3d& box,
                    const CarveOptions& options,
                    const VisibilityFactory& factory = {});
  // Starts from `start` instead of the full grid (options.resolution is not used; the visual
  // hull, when asked, is carved from `start`).
  IncrementalCarver(const std::vector<CalibratedView>& views,
                    Volume start,
                    const CarveOptions& options,
                    const VisibilityFactory& factory = {});

  // Takes the next voxel from the CVSVL and evaluates it if still solid: computes Vis(V) and its
  // consistency; if inconsistent, carves it, updates the surface and the rays of Vis(V), and
  // queues the voxels those rays reach. Returns false once the CVSVL is empty (converged).
  bool Step();

  // Carves every 26-connected component of solid voxels smaller than `min_voxels`: specks left in
  // empty space because their pixels agree by chance. Each voxel is carved as Step carves one
  // (the rays that ended in it step on and the voxels they reach are queued), so Step carries on
  // from there. Returns the voxels carved. Cost: one pass over the runs of solid voxels along x
  // (their rows' bits), then the voxels of the components carved.
  int64_t RemoveSmallComponents(int64_t min_voxels);

  // Carves every 26-connected component that no point of `points` lies in or beside (within one
  // voxel) although the model's density of such points (points per surface voxel, over the
  // components that hold any) predicts at least `min_expected` on its surface voxels, and whose
  // surface voxels are fewer than a quarter of the largest component's. Carved as
  // RemoveSmallComponents carves. Returns the voxels carved; `components` and `largest_expected`
  // (may be null) get how many components went and the most points one of them was expected to
  // hold. Cost: as RemoveSmallComponents'.
  int64_t RemoveUnsupportedComponents(const std::vector<SurfacePoint>& points,
                                      double min_expected,
                                      int64_t* components,
                                      double* largest_expected);

  // Colours every surface voxel from its current visible pixels (and measures the mean
  // reprojection error, surface_reprojection_error()).
  std::vector<ColouredVoxel> ColourSurface();
  double surface_reprojection_error() const { return surface_reprojection_error_; }

  const Volume& volume() const { return volume_; }
  const VisualHullStatistics& visual_hull() const { return visual_hull_; }
  const FreeSpaceStatistics& free_space() const { return free_space_; }
  const FreeSpaceStatistics& distant() const { return distant_; }
  // The ground pixels' rays (those of CarveOptions::distant_rays with a finite length).
  const FreeSpaceStatistics& ground_seen() const { return ground_seen_; }
  Volume* mutable_volume() { return &volume_; }
  Visibility& visibility() { return *visibility_; }
  // The ray-cast visibility, or nullptr with another method.
  RayCastVisibility* ray_visibility() { return ray_visibility_; }
  int passes() const { return passes_; }
  // Threads the carving runs on (1 unless batched or view-parallel ray casting).
  int threads() const { return batched_ || view_parallel_ ? workers_.num_groups() : 1; }
  // Where the threads' time went so far (see ViewWorkers::Times).
  ViewWorkers::Times worker_times() const { return workers_.times(); }
  int64_t evaluated() const { return evaluated_; }
  int64_t carved() const { return carved_; }
  // Evaluations that found a protected voxel inconsistent and kept it
  // (CarveOptions::protect_surface_points).
  int64_t protected_kept() const { return protected_kept_; }
  // Voxels under the ground (CarveOptions::ground), never carved by colour.
  int64_t ground_voxels() const { return ground_voxels_; }
  // Voxels below the plane beyond the ground's edge, carved before colouring (SplitBelowGround).
  int64_t beyond_ground_carved() const { return beyond_ground_carved_; }
  bool IsProtected(int64_t voxel) const {
    return !protected_.empty() && ((protected_[voxel >> 6] >> (voxel & 63)) & 1) != 0;
  }
  // The CVSVL's voxels (in batched carving, the last batch's arrivals join it in the next Step).
  size_t queue_size() const {
    return queue_.size() + heap_.size() + (batch_found_ ? batches_[current_].entries.size() : 0);
  }
  // Volume, visibility structures and the CVSVL at its largest so far.
  size_t MemoryBytes() const;
  // The mean reprojection error over usable pixels (see CarveStatistics); costs an evaluation of
  // every surface voxel.
  double MeanReprojectionError();

 private:
  void Enqueue(int64_t voxel);
  // The next voxel to evaluate, or false when the CVSVL is empty.
  bool Pop(int64_t* voxel);
  // V's consistency, with Vis(V) in vis_ (with incremental statistics, only when `need_vis`;
  // vis_ready_ says whether vis_ holds it).
  Consistency Evaluate(int64_t voxel, bool need_vis = true);
  // The test's verdict on V from its views' statistics, with the coverage rule and the patterns.
  // Reads only; safe on several threads.
  Consistency Judge(int64_t voxel, const std::vector<ViewColourStats>& stats) const;
  // Batched carving (CarveOptions::batch_voxels): one batch per Step.
  bool StepBatch();
  // Vis(V) into vis_ (and, with `gather`, its statistics into stats_).
  void FindVis(int64_t voxel, bool gather);
  // Carves a solid voxel whatever its consistency, updating visibility and queueing the voxels
  // whose visibility changed.
  void CarveAndQueue(int64_t voxel);
  // With incremental statistics: the colours of vis_'s pixels go to the voxels their rays reach.
  void AddArrivals();
  // View-parallel ray casting: one task over the views' groups that first steps the rays of
  // `advance` (when not null; the voxels they reach go to changed_), then finds Vis of
  // `vis_voxel` and its colour statistics (when >= 0; into vis_ and stats_).
  // With `advance_found` (and no `advance`), the rays of the Vis found are stepped instead, in
  // the same task; without `gather`, no statistics are gathered.
  void RunViewGroups(const std::vector<PixelRef>* advance,
                     int64_t vis_voxel,
                     bool gather = true,
                     bool advance_found = false);
  // With protection: whether V lies at or behind the known surface (within
  // kKnownSurfaceMarginVoxels) in a view of `stats` whose known depth covers V's centre.
  bool BehindKnownSurface(int64_t voxel, const std::vector<ViewColourStats>& stats) const;
  // The voxel Pop will hand out next if it is known now and still solid (fifo only), else -1.
  int64_t PeekNextSolid() const;
  // With vis_ holding Vis(V) and `colour` V's colour: the change of the reprojection error of
  // the pixels involved if V were carved (negative: carving explains them better).
  double ReprojectionChange(const Eigen::Vector3d& colour);
  Eigen::Vector3d PixelColour(const PixelRef& ref) const {
    const uint8_t* rgb = views_[ref.view].image.data + 3 * static_cast<size_t>(ref.pixel);
    return Eigen::Vector3d(rgb[0], rgb[1], rgb[2]);
  }

  // Per group of views, its own buffers (on cache lines of their own): what its views gave, one
  // after another, with where each view's part ends.
  struct BatchHit;
  struct alignas(64) GroupBuffers {
    std::vector<PixelRef> vis;
    std::vector<ViewColourStats> stats;
    // JudgeEntries: the entries' sums per view, entry by entry (entry i's from view_sums_begin[i]
    // on), and per entry the views gathered so far.
    std::vector<ViewColourStats> view_sums;
    std::vector<uint32_t> view_sums_begin;
    std::vector<uint32_t> view_sums_count;
    std::vector<int64_t> changed;
    std::vector<size_t> vis_end;
    std::vector<size_t> stats_end;
    std::vector<size_t> changed_end;
  };

  const std::vector<CalibratedView>& views_;
  VisualHullStatistics visual_hull_;  // declared before volume_: filled while volume_ is built
  FreeSpaceStatistics free_space_;    // likewise
  FreeSpaceStatistics distant_;       // likewise
  FreeSpaceStatistics ground_seen_;   // likewise
  int64_t beyond_ground_carved_ = 0;  // likewise
  std::vector<int64_t> ground_held_;   // likewise: the voxels under the ground, until protected
  // Per view, KnownSurfaceDepths: with protection, or for the distant rays (made with the volume,
  // which is declared after it, by PreCarved); empty otherwise.
  std::vector<cv::Mat> known_depth_;
  Volume volume_;
  ViewWorkers workers_;  // declared before visibility_, which uses it to set up rays
  std::unique_ptr<Visibility> visibility_;
  RayCastVisibility* ray_visibility_;  // visibility_ when it is ray casting, else nullptr
  // Ray casting spread over workers_ (see CarveOptions::num_threads): in batches, or one voxel
  // at a time by views.
  bool batched_ = false;
  int batch_voxels_ = 1;
  bool view_parallel_ = false;
  // A voxel of a batch and the verdict on it.
  struct BatchEntry {
    int64_t voxel = 0;
    Consistency consistency;
    bool carve = false;
    bool kept_protected = false;      // inconsistent, but known surface
    double reprojection_error = 0.0;  // ColourSurface: summed |pixel - colour| over Vis
    int num_pixels = 0;               // |Vis|
  };
  struct Batch {
    std::vector<BatchEntry> entries;
    // The entries' voxel coordinates, kept apart: all that the view tasks read of a batch. Within
    // the entries (120 bytes each), the threads fetched every entry's cache lines from the
    // calling thread, which had just written them (forming the batch, judging it): a cache line
    // between two cores costs 90-470 ns here (carve_benchmark's round trip). Apart, 12 bytes a
    // voxel, written once.
    std::vector<Eigen::Vector3i> coordinates;
    void Add(int64_t voxel, const VoxelGrid& grid) {
      entries.emplace_back();
      entries.back().voxel = voxel;
      coordinates.push_back(grid.Voxel(voxel));
    }
    void Clear() {
      entries.clear();
      coordinates.clear();
    }
  };
  // Where a voxel's pixels lie in one view's buffer: [begin, end). A view has fewer pixels than
  // 2^32.
  struct Span {
    uint32_t begin = 0, end = 0;
  };
  // A voxel of a batch that a view sees pixels of: its index in the batch and the sums of their
  // colours and squared colours. The channels are 8-bit, so integer sums are exact (as the
  // doubles they become are) and take half the bytes the judging thread fetches from the one
  // that found them. A voxel with more than kMaxHitPixels pixels in a view (where a square sum
  // could overflow) gets several records in a row, merged when judged.
  static constexpr uint32_t kMaxHitPixels = 65535;
  struct BatchHit {
    int32_t k = 0;
    uint32_t count = 0;
    uint32_t sum[3] = {0, 0, 0};
    uint32_t sum_squares[3] = {0, 0, 0};
  };
  // Per view, written only by the thread that runs the view (mostly the same one from task to
  // task, see RunViewTask): the Vis pixels of the two batches in flight (the one being carved
  // and the next), each entry's span in them and the entries seen (in batch order, with their
  // statistics); the voxels its rays reached, per carved entry (in batch_carved_ order); its time
  // since the last sorting. A task so hands the other threads little more than the statistics
  // the judging needs. (A record per view and voxel of the batch, which the judging read and the
  // next task wrote over, had the two cores trade its cache lines: two threads did 40-50% more
  // work than one.)
  // A carved voxel whose rays in a view reached voxels: its index in batch_carved_, and where
  // they end in the view's reached voxels (they begin where the run before ends).
  struct ReachedRun {
    uint32_t j = 0;
    uint32_t end = 0;
  };
  // What a view's task hands the calling thread (JudgeEntries, QueuePendingArrivals), per
  // slot, on a cache line of its own, written once a task: the vectors' own fields share lines
  // with the rest of ViewBuffers, which the view's thread writes all through its task (each
  // push_back), so the calling thread's reading them cost the view's thread a round trip
  // between the cores on its next write.
  struct alignas(64) ViewOutput {
    const BatchHit* hits[2] = {nullptr, nullptr};
    const int64_t* reached[2] = {nullptr, nullptr};
    const ReachedRun* runs[2] = {nullptr, nullptr};
    uint32_t num_hits[2] = {0, 0};
    uint32_t num_runs[2] = {0, 0};
  };
  struct alignas(64) ViewBuffers {
    std::vector<PixelRef> vis[2];
    std::vector<Span> spans[2];
    std::vector<BatchHit> hits[2];
    std::vector<Footprint> footprints;
    std::vector<int> seen;  // the batch's voxels with a non-empty footprint in the view
    // By the carved batch's slot: the voxels reached, and the runs of them per carved voxel
    // (only for those whose rays reached any: a record per carved voxel, mostly empty, had the
    // other thread's reading cost this one's next writing a cache line's round trip each).
    std::vector<int64_t> reached[2];
    std::vector<ReachedRun> reached_runs[2];
    int64_t nanoseconds = 0;
  };
  // Batched carving is a pipeline of two batches: batches_[current_] has its Vis found (when
  // batch_found_) and is judged and carved next; in the same task that steps its carved voxels'
  // rays, each view then finds the Vis of the next batch (taken from the queue after the carve,
  // before the arrivals are queued; its voxels keep their queued bits until the arrivals of the
  // carve before their judging are queued, so that these do not queue them again: their Vis
  // already holds the new pixels). A batch's arrivals are queued in the next task, by the
  // calling thread while the others step rays and find Vis (QueuePendingArrivals): the same
  // queue as queueing them at once (see StepBatch).
  // Up to `batch_voxels_` solid voxels from the queue into `batch`, their queued bits left set.
  void FormBatch(Batch* batch);
  // One task over the views: steps the rays of `carving`'s carved voxels (when not null; Vis in
  // slot `carving_slot`), then finds the Vis of `finding`'s voxels (when not null; into slot
  // `finding_slot`). Views are claimed one at a time, each group first its own (view v
  // belongs to group v mod G, so that a view's rays stay in one core's cache from batch to
  // batch), then any left, the costliest first. Which group takes a view never changes what is
  // computed.
  void RunViewTask(Batch* carving, int carving_slot, Batch* finding, int finding_slot);
  // Judges every voxel of `batch` (Vis found in `slot`); with `colouring`, also each one's
  // reprojection error. The mean-colour test is a few arithmetic operations a view, less than a
  // hand-over to the workers costs: it runs on the calling thread; the pattern test and
  // colouring, which read pixels, run on every group, which claim voxels.
  void JudgeEntries(Batch* batch, int slot, bool colouring);
  // Every kSortTasks tasks: sorts claim_order_ by the views' time since the last sorting, the
  // costliest first.
  void SortViewsByCost();
  // Queues the voxels that the rays of the last carved batch reached (in slot pending_slot_,
  // from pending_carved_ carved voxels), unless queued already or empty.
  void QueuePendingArrivals();
  // Queues the pending arrivals, then puts a batch found but not yet judged back at the front of
  // the queue (before carving outside the pipeline: its Vis would go stale).
  void ReturnPendingBatch();
  int pending_slot_ = -1;  // -1: no arrivals pending
  size_t pending_carved_ = 0;
  std::vector<size_t> pending_next_run_;  // QueuePendingArrivals: per view, its next run
  Batch batches_[2];
  std::vector<int> batch_carved_;  // indices into the current batch, in queue order
  int current_ = 0;
  bool batch_found_ = false;
  std::vector<ViewBuffers> view_buffers_;
  std::vector<ViewOutput> view_outputs_;
  std::vector<int> claim_order_;  // views, costliest first
  std::unique_ptr<std::atomic<uint8_t>[]> view_claimed_;
  int tasks_since_sort_ = 0;
  std::vector<GroupBuffers> groups_;
  std::vector<size_t> advance_begin_;  // per view: where its pixels start in the rays to step
  int64_t prefetched_ = -1;  // the voxel whose Vis and statistics vis_ and stats_ already hold
  std::unique_ptr<VoxelColourSums> sums_;  // with incremental statistics
  bool vis_ready_ = false;
  ConsistencyTest test_;
  bool patterns_ = false;  // kPatchCorrelation
  double min_coverage_ = 0.0;
  int min_views_ = 2;
  double pattern_threshold_ = 0.5;
  CarveOrder order_;
  CarveDecision decision_;
  double threshold_;
  int64_t usable_pixels_ = 0;
  double surface_reprojection_error_ = -1.0;
  std::vector<std::pair<int64_t, int>> arrivals_;  // (voxel reached next, index into vis_)
  std::vector<PixelRef> next_vis_;
  std::deque<int64_t> queue_;                             // first in, first out
  std::priority_queue<std::pair<int64_t, int64_t>> heap_;  // (|Vis|, voxel), most first
  std::vector<uint64_t> queued_;
  std::vector<uint64_t> protected_;  // a bit per voxel; empty without protection
  int64_t protected_kept_ = 0;
  int64_t ground_voxels_ = 0;
  size_t max_queue_ = 0;
  int64_t evaluated_ = 0;
  int64_t carved_ = 0;
  int passes_ = 1;
  std::vector<PixelRef> vis_;
  std::vector<ViewColourStats> stats_;
  std::vector<int64_t> exposed_;
  std::vector<int64_t> changed_;
};

// The visibility of `method` over `volume` (both must outlive it); `workers`, when given, set
// up ray casting's rays in parallel.
std::unique_ptr<Visibility> MakeVisibility(const std::vector<CalibratedView>& views,
                                           const Volume& volume,
                                           const CarveOptions& options,
                                           ViewWorkers* workers = nullptr);

}  // namespace raycarve
