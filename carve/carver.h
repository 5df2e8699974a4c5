#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <queue>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "calib/calibrated_view.h"
#include "carve/consistency.h"
#include "carve/silhouette_repair.h"
#include "carve/level_of_detail.h"
#include "carve/ray_cast_visibility.h"
#include "carve/surface_evidence.h"
#include "carve/view_workers.h"
#include "carve/voxel_colour_sums.h"
#include "carve/free_space.h"
#include "carve/visual_hull.h"
#include "carve/volume.h"

namespace raycarve {

// How visibility is kept: the seed paper's ray casting or one of its two baselines. They share
// everything else (grid, surface, footprints, consistency, colouring).
enum class CarveMethod {
  kRay,     // ray casting: an image of rays per view, stepped only where a voxel was carved
  kGvc,     // GVC: item buffers re-rendered every pass, every surface voxel judged per pass
  kGvcLdi,  // GVC-LDI: per-pixel depth-sorted lists of surface voxels, updated incrementally
};
std::string CarveMethodToString(CarveMethod method);
bool CarveMethodFromString(const std::string& text, CarveMethod* method);

// The order in which the CVSVL hands out voxels (the seed paper's section 4).
enum class CarveOrder {
  kFifo,           // first in, first out
  kVisiblePixels,  // most visible pixels first: most evidence first
};
std::string CarveOrderToString(CarveOrder order);
bool CarveOrderFromString(const std::string& text, CarveOrder* order);

// How a voxel is judged (the seed paper's section 4).
enum class CarveDecision {
  kThreshold,     // carve when the consistency error exceeds the threshold
  kReprojection,  // also carve consistent voxels when that lowers the pixels' reprojection error
};
std::string CarveDecisionToString(CarveDecision decision);
bool CarveDecisionFromString(const std::string& text, CarveDecision* decision);

// Incremental voxel colouring with ray-cast visibility (Batchelor, Mukundan, Green).
// Known surface (CarveOptions::protect_surface_points): around a surface point's projection in a
// view that saw it, within this many of its projected voxel widths, the surface is taken to lie no
// farther than the farthest such point; a voxel closer than that by less than the margin (in
// voxels) is at or behind the known surface in that view and is not carved by colour.
constexpr double kKnownSurfaceRadiusVoxels = 2.0;
// ... or this many times the view's spacing of the known surface (the median distance from an
// observation to its nearest neighbour in that photo), when that is wider: finer grids need the
// same cover of the photo.
constexpr double kKnownSurfaceRadiusSpacings = 1.0;
constexpr double kKnownSurfaceMarginVoxels = 1.0;
// The largest consistent error (RGB units) where none is given or can be chosen from the data.
constexpr double kDefaultThreshold = 30.0;

struct CarveOptions {
  // The smallest shorter side of a photo reduced for a coarse level of detail.
  static constexpr int kMinReducedSide = 48;

  CarveMethod method = CarveMethod::kRay;
  // Voxels along the longest axis of the box; voxels are cubes.
  int resolution = 128;
  // How visible pixels are judged (see consistency.h).
  ConsistencyMethod consistency = ConsistencyMethod::kMeanColour;
  // Largest consistent error, in RGB units (0-255). Negative: nothing is consistent, so every
  // voxel seen by min_views views is carved.
  double threshold = kDefaultThreshold;
  // consistency kPatchCorrelation: a voxel that passes the colour test but whose views see
  // texture is carved when 1 - NCC of their patterns exceeds this (0..2).
  double pattern_threshold = 0.5;
  // Adaptive allowance: the threshold grows by this times the voxel's within-view colour spread
  // (see ConsistencyTest); 0 holds every voxel to `threshold`.
  double adaptive_threshold = 0.0;
  // Views a voxel must be seen by to be judged; voxels seen by fewer stay.
  int min_views = 2;
  // A voxel is judged only when at least min_views views each see this share of its projected
  // outline (its visible pixels against the area of the cube's projection); otherwise it stays.
  // A voxel seen through a small hole shows the views the hole's rim, not itself: judging it lets
  // one wrong carve drill a tunnel. 0: any pixel counts.
  double min_coverage = 0.0;
  // After the final level, give back to every masked view's object pixels the model that colour
  // carving took from their rays (RepairSilhouettes): holes the masks contradict are closed.
  bool repair_silhouettes = false;
  // Refuse a grid whose carving structures would need more memory than this (GiB).
  double max_memory_gib = 8.0;
  // With ray casting, how Vis(V) is found (see ray_cast_visibility.h); the carving is the same
  // either way.
  VisLookup vis_lookup = VisLookup::kFootprint;
  // When views carry masks: carve the silhouettes' visual hull before colouring (background
  // pixels are always left out of Vis(V) and consistency).
  bool visual_hull = true;
  CarveOrder order = CarveOrder::kFifo;
  // kReprojection (ray casting only; after Slabaugh et al., carving only): besides what the
  // threshold carves, a consistent V is carved when the pixels of Vis(V) would be explained
  // better by the voxels their rays reach next (each such voxel's colour recomputed with them)
  // than by V: the summed |pixel - colour| of the pixels involved drops. A pixel whose ray would
  // leave the volume costs `threshold`. Voxels seen by fewer than min_views views are kept.
  // (Alone, the reprojection test stalls in empty space, where V and the voxels behind it
  // explain the pixels equally badly: measured, it carved 4% of the demo volume.)
  CarveDecision decision = CarveDecision::kThreshold;
  // Levels of detail (Prock and Dyer): 1 carves at `resolution` directly; L > 1 carves at
  // resolution / 2^(L-1) first, then augments by lod_band voxels, subdivides and carves again, up
  // to `resolution` (which must be divisible by 2^(L-1)). 0 (kAutomaticLevels): as many levels
  // as keep the coarsest at 64 voxels or more (level_of_detail.h; the command line's default).
  int lod_levels = 1;
  int lod_band = 1;
  // With levels of detail: a level whose voxels are f = 2^k times the final ones carves the
  // photos reduced f times (block means; ReduceView), so that a voxel covers about as many
  // pixels at every level (fewer while any photo's shorter side would drop below
  // kMinReducedSide pixels). Off: every level carves the full photos.
  bool lod_reduce_images = true;
  // After the final level converges: carve every 26-connected component of solid voxels with
  // fewer voxels than this (specks in empty space whose pixels agree by chance), then carry on
  // carving from what they hid; repeated while any is found (at most 4 rounds). 0: keep all.
  int min_component_voxels = 0;
  // After that: carve every 26-connected component that holds none of surface_points (within a
  // voxel) where the density of the points on the model's surface predicts at least this many,
  // and whose surface is below a quarter of the largest component's: hull leftovers floating
  // beside the object, which no photo saw texture on. 0: keep all.
  double unsupported_component_points = 0.0;
  // With levels of detail: a level whose voxels are 2^k times the final ones judges with
  // threshold x lod_threshold_scale^k. A coarse voxel straddles more texture edges and spans more
  // depth, so its views' mean colours disagree more even on the true surface; at the final
  // threshold the coarse levels carve into the object, and what they carve no finer level puts
  // back beyond the band. The coarse levels need only remove what is clearly empty; the final
  // level judges with `threshold`. 1: every level uses `threshold`. Measured in the README
  // (the demo at 128 voxels, threshold 30: completeness 44% with 1, 94.4% with 1.1, 93.7% with
  // 1.2, 92.7% with 1.5, 92.0% in one level).
  double lod_threshold_scale = 1.2;
  // Threads for ray casting with the footprint lookup and fifo order (see batch_voxels). The
  // carving is identical for any count. < 1: one per core. Other methods, ray lists and the
  // evidence order use one.
  int num_threads = 1;
  // Ray casting with the footprint lookup, fifo order and the threshold decision, without
  // incremental statistics: the CVSVL is handed out this many voxels at a time. The voxels of a
  // batch are judged at once against the rays as they stand (Vis(V) found and tested for each, on
  // every thread), the inconsistent ones are carved in queue order, then the rays that ended in
  // them step on (on every thread) and the voxels they reach are queued, batch by batch in queue
  // order. A voxel of the batch that a ray of another carved voxel reaches is queued again and
  // judged with its new pixels, as any voxel whose visibility changed is. The batch is the unit
  // of work handed to the threads, so it does not depend on their number and neither does the
  // carving. 1: the seed paper's one voxel at a time (its threads then share each voxel's views:
  // a hand-over per voxel, which costs more than it saves on fine grids). Measured in
  // docs/studies/carving.md.
  int batch_voxels = 64;
  // Ray casting: keep colour statistics per voxel and view incrementally (voxel_colour_sums.h):
  // evaluating a voxel reads its sums, and Vis(V) is found only for voxels carved (or judged by
  // the reprojection decision). Same carving, 56 bytes per view and voxel holding rays.
  bool incremental_statistics = false;
  // Points known to lie on the surface (reliable sparse points, with the views that saw them:
  // indices into the carve's views). Used by auto_threshold and protect_surface_points.
  std::vector<SurfacePoint> surface_points;
  // Choose each level's threshold (and pattern_threshold) from the data (EstimateThreshold over
  // surface_points at that level's grid and photos): with masks, the auto_threshold_quantile of
  // the errors of the voxels known to be on the surface; without, the equal-error threshold
  // between them and the voxels just in front of them. `threshold` (and lod_threshold_scale) and
  // pattern_threshold are the fallback where fewer than 20 points can be judged.
  bool auto_threshold = false;
  double auto_threshold_quantile = 0.99;
  // kPatchCorrelation: choose pattern_threshold from the data as auto_threshold does, also when
  // `threshold` is given.
  bool auto_pattern_threshold = false;
  // Voxels holding a surface point are never carved by the consistency test (the visual hull and
  // the removal of small components still carve them): known surface stops carving that runs
  // away through one wrong carve.
  bool protect_surface_points = false;
  // Free space from the sparse points (> 0): a surface point seen by a view was seen across
  // empty space, so the voxels on the sight line from the view's centre to the point are carved
  // before colouring, up to this many voxels short of the point. 0: off.
  double free_space_margin_voxels = 0.0;

  bool IsValid(std::string* reason) const;
};

struct CarveProgress {
  int level = 0;   // with levels of detail: the level carving now, 0 the coarsest
  int levels = 1;
  int64_t evaluated = 0;
  int64_t carved = 0;
  int64_t queued = 0;
  double seconds = 0.0;  // since carving started (after set-up)
};

// One point of the carving curve (the paper's Figure 6).
struct CurveSample {
  double seconds = 0.0;
  // Voxels carved so far, besides the visual hull's. With levels of detail, in voxels of the
  // final resolution (a coarse voxel counts for the fine voxels it holds), so that the curve
  // steps back where a refinement's band puts voxels back.
  int64_t carved = 0;
  int64_t evaluated = 0;
};

struct CarveStatistics {
  std::string visibility;  // "ray (footprint)", "ray (ray_lists)", "gvc" or "gvc_ldi"
  int passes = 1;          // GVC: item-buffer renders (passes over the surface); others 1
  int threads = 1;         // threads of the final level's carving
  int views_with_masks = 0;
  SilhouetteRepairSummary silhouette_repair;  // CarveOptions::repair_silhouettes
  int64_t visual_hull_carved = 0;    // voxels removed by the silhouette pre-carve
  // Voxels removed by the sparse points' sight lines (CarveOptions::free_space_margin_voxels),
  // summed over the levels (each level's own voxels), and at the first level; the sight lines
  // that crossed the grid; the time (part of set-up).
  int64_t free_space_carved = 0;
  int64_t free_space_level0_carved = 0;
  int64_t free_space_sight_lines = 0;
  double free_space_seconds = 0.0;
  std::string FreeSpaceSummary() const;  // one line for the log
  std::string FloaterSummary() const;    // likewise, for the components without sparse points
  int64_t component_carved = 0;  // small components removed (CarveOptions::min_component_voxels)
  // Components removed for holding no sparse point (CarveOptions::unsupported_component_points):
  // how many, their voxels, and the points they were expected to hold (the largest).
  int64_t unsupported_components = 0;
  int64_t unsupported_component_carved = 0;
  double unsupported_largest_expected = 0.0;
  double visual_hull_seconds = 0.0;  // its time (part of set-up)
  Eigen::Vector3i dimensions = Eigen::Vector3i::Zero();
  double voxel_size = 0.0;
  int64_t num_voxels = 0;
  int64_t initial_surface = 0;
  int64_t final_surface = 0;
  int64_t final_solid = 0;
  int64_t carved = 0;     // voxels removed: the grid's voxels less the final solid ones
  int64_t evaluated = 0;  // evaluations, over every level
  int64_t visible_surface = 0;  // final surface voxels seen by at least one pixel
  double setup_seconds = 0.0;   // volume and rays
  // The carving loops: the convergence time. With levels of detail, everything after the first
  // level's set-up (refinements and later set-ups too).
  double carve_seconds = 0.0;
  double colour_seconds = 0.0;  // colouring the final surface
  // Where the threads' time went in carving and colouring (every level; ViewWorkers::Times): the
  // wall time of the parallel sections, and per thread its work in them (its waiting is the rest).
  // Set-up, and the serial parts between sections, are outside.
  double parallel_seconds = 0.0;
  std::vector<double> thread_work_seconds;
  int64_t parallel_runs = 0;
  int64_t inline_runs = 0;  // sections run on one thread because the others fell behind
  size_t peak_memory_bytes = 0;  // volume, visibility structures and the CVSVL
  std::vector<CurveSample> curve;
  std::vector<LevelStatistics> levels;  // one per level of detail (one without)
  // The mean over usable pixels of |pixel - colour of the voxel it sees| (RGB), a pixel seeing
  // no voxel counting `threshold`: after carving, and (with the reprojection decision, as it
  // costs a pass over the surface) before; -1 when not computed.
  double reprojection_error_before = -1.0;
  double reprojection_error_after = -1.0;

  std::string Summary() const;
  // "2 threads", with the share of the parallel runs the calling thread ran alone where the
  // workers were left (ViewWorkers: the other cores were busy).
  std::string ThreadsText() const;
};

struct ColouredVoxel {
  int64_t index = 0;
  Eigen::Vector3f colour = Eigen::Vector3f::Zero();  // RGB 0-255, mean of the visible pixels
  int num_views = 0;
  int num_pixels = 0;  // 0: no view sees this surface voxel (it is not coloured)
};

struct CarveResult {
  explicit CarveResult(const VoxelGrid& grid) : volume(grid) {}
  Volume volume;
  std::vector<ColouredVoxel> surface;  // every final surface voxel, in index order
  CarveStatistics statistics;
};

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
  // from there. Returns the voxels carved. Cost: one pass over the solid voxels.
  int64_t RemoveSmallComponents(int64_t min_voxels);

  // Carves every 26-connected component that no point of `points` lies in or beside (within one
  // voxel) although the model's density of such points (points per surface voxel, over the
  // components that hold any) predicts at least `min_expected` on its surface voxels, and whose
  // surface voxels are fewer than a quarter of the largest component's. Carved as
  // RemoveSmallComponents carves. Returns the voxels carved; `components` and `largest_expected`
  // (may be null) get how many components went and the most points one of them was expected to
  // hold. Cost: one pass over the solid voxels.
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
  std::vector<cv::Mat> known_depth_;  // per view, KnownSurfaceDepths; empty without protection
  int64_t protected_kept_ = 0;
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

// Estimates the memory of carving `views` over `box` with `options` and returns false, with a
// reason giving the sizes, when the options are invalid or the estimate exceeds
// options.max_memory_gib.
bool CheckCarveFits(const std::vector<CalibratedView>& views,
                    const Eigen::AlignedBox3d& box,
                    const CarveOptions& options,
                    std::string* reason);

// How much of a box the views see, from a lattice of 17^3 points over it: per view the share of
// the points in front of its camera and on a valid pixel of its photo, and the share of the
// points that at least `min_views` views see.
struct BoxCoverage {
  std::vector<double> view_share;  // per view, in view order
  double seen_share = 0.0;         // by min_views views or more
};
BoxCoverage MeasureBoxCoverage(const std::vector<CalibratedView>& views,
                               const Eigen::AlignedBox3d& box,
                               int min_views);

// Carves the volume over `box` seen by `views` until no voxel whose visibility changed is
// inconsistent. `progress` (optional) is called about every `progress_interval_seconds` of
// carving. Options must pass CheckCarveFits (CHECKed).
CarveResult CarveVolume(const std::vector<CalibratedView>& views,
                        const Eigen::AlignedBox3d& box,
                        const CarveOptions& options,
                        const std::function<void(const CarveProgress&)>& progress = {},
                        double progress_interval_seconds = 1.0);

}  // namespace raycarve
