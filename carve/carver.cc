#include "carve/carver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include <glog/logging.h>

#include "carve/free_space.h"
#include "carve/item_buffer_visibility.h"
#include "carve/layered_depth_visibility.h"
#include "carve/patch_correlation.h"
#include "carve/ray_image.h"

namespace raycarve {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

constexpr double kBytesPerRay = 4.0;
constexpr double kBytesPerListedRay = 8.0;
// GVC: a 4-byte item per pixel (and one view's depth buffer, counted as 4 more bytes a pixel).
constexpr double kBytesPerItemPixel = 8.0;
// GVC-LDI: a 4-byte head per pixel and 12-byte entries; a ray crosses the surface a few times
// (entering and leaving the object, more on concave parts): estimated at 4 entries a pixel.
constexpr double kBytesPerLayeredPixel = 4.0 + 4 * 12.0;
// Solid, surface and in-queue bits, plus a generous byte for the CVSVL's entries.
constexpr double kBytesPerVoxel = 3.0 / 8.0 + 1.0;
constexpr double kBytesPerListedVoxel = kBytesPerVoxel + 4.0;
// Batched carving: voxels a group claims at once for judging (see ClaimItems), and the tasks
// between two sortings of the views by their cost (SortViewsByCost).
constexpr int kClaimChunk = 8;
// Finding Vis: how many voxels ahead their rays and photo rows are fetched.
constexpr int kPrefetchAhead = 3;
constexpr int kSortTasks = 64;

int64_t ElapsedNanoseconds(Clock::time_point since) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - since).count();
}

// Appends to `stats` the colour statistics of pixels [begin, end), grouped view by view (a new
// entry wherever the view changes).
void GatherColours(const std::vector<CalibratedView>& views,
                   const PixelRef* begin,
                   const PixelRef* end,
                   std::vector<ViewColourStats>* stats) {
  for (const PixelRef* ref = begin; ref != end; ++ref) {
    if (ref == begin || ref->view != (ref - 1)->view) {
      stats->emplace_back();
      stats->back().view = static_cast<int>(ref->view);
    }
    const uint8_t* rgb = views[ref->view].image.data + 3 * static_cast<size_t>(ref->pixel);
    stats->back().Add(Eigen::Vector3d(rgb[0], rgb[1], rgb[2]));
  }
}

// Per view, the depth of the known surface near each pixel: around each surface point's
// projection, within kKnownSurfaceRadiusVoxels of its projected voxel width or
// kKnownSurfaceRadiusSpacings of the view's observation spacing, whichever is wider, the farthest
// depth of the points there (0: no point near). Empty for views no point names.
std::vector<cv::Mat> KnownSurfaceDepths(const std::vector<CalibratedView>& views,
                                        const VoxelGrid& grid,
                                        const std::vector<SurfacePoint>& points) {
  // Per view, the projections (x, y, depth) of the points it saw.
  std::vector<std::vector<Eigen::Vector3d>> seen(views.size());
  for (const SurfacePoint& point : points) {
    if (!grid.Contains(grid.VoxelOf(point.xyz))) continue;
    for (int v : point.views) {
      const Eigen::Vector3d pixel = views[v].P * point.xyz.homogeneous();
      if (pixel.z() > 0.0) seen[v].emplace_back(pixel.x() / pixel.z(), pixel.y() / pixel.z(), pixel.z());
    }
  }
  std::vector<cv::Mat> depths(views.size());
  std::vector<double> nearest;
  for (size_t v = 0; v < views.size(); ++v) {
    const CalibratedView& view = views[v];
    if (seen[v].empty()) continue;
    // The spacing of the known surface in this view: the median distance from an observation to
    // its nearest neighbour (brute force; a few thousand points a view at most).
    nearest.clear();
    for (size_t i = 0; i < seen[v].size(); ++i) {
      double best = std::numeric_limits<double>::infinity();
      for (size_t j = 0; j < seen[v].size(); ++j) {
        if (i != j) best = std::min(best, (seen[v][i].head<2>() - seen[v][j].head<2>()).squaredNorm());
      }
      if (std::isfinite(best)) nearest.push_back(std::sqrt(best));
    }
    double spacing = 0.0;
    if (!nearest.empty()) {
      std::nth_element(nearest.begin(), nearest.begin() + nearest.size() / 2, nearest.end());
      spacing = nearest[nearest.size() / 2];
    }
    depths[v] = cv::Mat::zeros(view.height, view.width, CV_32F);
    const double focal = 0.5 * (view.K(0, 0) + view.K(1, 1));
    for (const Eigen::Vector3d& at : seen[v]) {
      const double x = at.x(), y = at.y();
      const double radius = std::max(kKnownSurfaceRadiusVoxels * focal * grid.voxel_size() / at.z(),
                                     kKnownSurfaceRadiusSpacings * spacing);
      const int r = static_cast<int>(std::ceil(radius));
      const int c0 = static_cast<int>(std::floor(x)), r0 = static_cast<int>(std::floor(y));
      for (int row = std::max(0, r0 - r); row <= std::min(view.height - 1, r0 + r); ++row) {
        float* line = depths[v].ptr<float>(row);
        for (int col = std::max(0, c0 - r); col <= std::min(view.width - 1, c0 + r); ++col) {
          const double dx = col + 0.5 - x, dy = row + 0.5 - y;
          if (dx * dx + dy * dy > radius * radius) continue;
          line[col] = std::max(line[col], static_cast<float>(at.z()));
        }
      }
    }
  }
  return depths;
}

// Whether `options` carve in batches (CarveOptions::batch_voxels), given ray casting that finds
// Vis by footprints.
bool Batched(const CarveOptions& options) {
  return options.batch_voxels > 1 && options.method == CarveMethod::kRay &&
         options.vis_lookup == VisLookup::kFootprint && options.order == CarveOrder::kFifo &&
         options.decision == CarveDecision::kThreshold && !options.incremental_statistics;
}

// Calls work(view) for every view on `workers`, the groups claiming views one at a time: each
// group first its own (view v belongs to group v mod G, so that a view's rays stay in one core's
// cache from task to task), then any left, in `order` (the costliest first). Each group first
// calls lead(group), which must touch nothing another group's calls do (while the calling
// thread's group 0 leads, the others claim the views it would have taken).
template <typename Work, typename Lead>
void ClaimViews(ViewWorkers& workers, const std::vector<int>& order,
                std::atomic<uint8_t>* claimed, Work work, Lead lead) {
  for (int view : order) claimed[view].store(0, std::memory_order_relaxed);
  auto task = [&](int group) {
    lead(group);
    for (int pass = 0; pass < 2; ++pass) {
      for (int view : order) {
        if (pass == 0 && workers.GroupOf(view) != group) continue;
        if (claimed[view].load(std::memory_order_relaxed) != 0 ||
            claimed[view].exchange(1, std::memory_order_relaxed) != 0) {
          continue;
        }
        work(view);
      }
      if (workers.num_groups() == 1) break;
    }
  };
  workers.Run(task);
}

// Removes from `values` [0, n) every value seen earlier in it, keeping the order of the rest;
// returns how many are left. Neighbouring pixels' rays mostly reach the same voxels, and queueing
// a voxel twice in a row is a no-op: done on the workers, this spares the serial queueing most of
// its work without changing what is queued. (Short runs checked in full, longer ones against
// the previous value only.)
size_t KeepFirstOccurrences(int64_t* values, size_t n) {
  constexpr size_t kFullCheck = 64;
  size_t kept = 0;
  for (size_t i = 0; i < n; ++i) {
    bool seen = false;
    if (n <= kFullCheck) {
      for (size_t j = 0; j < kept && !seen; ++j) seen = values[j] == values[i];
    } else {
      seen = kept > 0 && values[kept - 1] == values[i];
    }
    if (!seen) values[kept++] = values[i];
  }
  return kept;
}

// The grid of `options` over `box`, once the carving is known to fit (CHECKed).
VoxelGrid CheckedGrid(const std::vector<CalibratedView>& views,
                      const Eigen::AlignedBox3d& box,
                      const CarveOptions& options) {
  std::string reason;
  CHECK(CheckCarveFits(views, box, options, &reason)) << reason;
  return VoxelGrid(box, options.resolution);
}

// The starting volume less the visual hull's outside (when asked and masked) and less the
// sparse points' sight lines (when asked).
Volume PreCarved(const std::vector<CalibratedView>& views,
                 Volume volume,
                 const CarveOptions& options,
                 VisualHullStatistics* hull,
                 FreeSpaceStatistics* free_space) {
  if (options.visual_hull) *hull = CarveVisualHull(views, &volume, options.num_threads);
  if (options.free_space_margin_voxels > 0.0 && !options.surface_points.empty()) {
    *free_space = CarveFreeSpace(views, options.surface_points, options.free_space_margin_voxels,
                                 &volume, options.num_threads);
  }
  return volume;
}

// How many times a level's photos are reduced: the level's voxel scale, halved while any photo's
// shorter side would fall below CarveOptions::kMinReducedSide.
int ImageFactor(const std::vector<CalibratedView>& views, int level_resolution, int resolution) {
  int factor = resolution / level_resolution;
  int shortest = std::numeric_limits<int>::max();
  for (const CalibratedView& view : views) shortest = std::min({shortest, view.width, view.height});
  while (factor > 1 && shortest / factor < CarveOptions::kMinReducedSide) factor /= 2;
  return factor;
}

}  // namespace

std::string CarveStatistics::FreeSpaceSummary() const {
  std::ostringstream text;
  text << "free space: " << free_space_sight_lines << " sight lines from the photos to the sparse "
       << "points they saw carved " << free_space_carved << " voxels (" << free_space_level0_carved
       << " at the first level) in " << free_space_seconds << " s";
  return text.str();
}

std::string CarveStatistics::FloaterSummary() const {
  std::ostringstream text;
  text << "floaters: " << unsupported_components << " pieces of the model without a sparse point ("
       << unsupported_component_carved << " voxels; the largest was expected to hold "
       << unsupported_largest_expected << " at the model's density) carved";
  return text.str();
}

std::string CarveMethodToString(CarveMethod method) {
  switch (method) {
    case CarveMethod::kRay:
      return "ray";
    case CarveMethod::kGvc:
      return "gvc";
    case CarveMethod::kGvcLdi:
      return "gvc_ldi";
  }
  return "unknown";
}

bool CarveMethodFromString(const std::string& text, CarveMethod* method) {
  for (CarveMethod candidate : {CarveMethod::kRay, CarveMethod::kGvc, CarveMethod::kGvcLdi}) {
    if (text == CarveMethodToString(candidate)) {
      *method = candidate;
      return true;
    }
  }
  return false;
}

std::string CarveDecisionToString(CarveDecision decision) {
  return decision == CarveDecision::kThreshold ? "threshold" : "reprojection";
}

bool CarveDecisionFromString(const std::string& text, CarveDecision* decision) {
  for (CarveDecision candidate : {CarveDecision::kThreshold, CarveDecision::kReprojection}) {
    if (text == CarveDecisionToString(candidate)) {
      *decision = candidate;
      return true;
    }
  }
  return false;
}

std::string CarveOrderToString(CarveOrder order) {
  return order == CarveOrder::kFifo ? "fifo" : "visible_pixels";
}

bool CarveOrderFromString(const std::string& text, CarveOrder* order) {
  for (CarveOrder candidate : {CarveOrder::kFifo, CarveOrder::kVisiblePixels}) {
    if (text == CarveOrderToString(candidate)) {
      *order = candidate;
      return true;
    }
  }
  return false;
}

std::unique_ptr<Visibility> MakeVisibility(const std::vector<CalibratedView>& views,
                                           const Volume& volume,
                                           const CarveOptions& options,
                                           ViewWorkers* workers) {
  switch (options.method) {
    case CarveMethod::kGvc:
      return std::make_unique<ItemBufferVisibility>(views, volume);
    case CarveMethod::kGvcLdi:
      return std::make_unique<LayeredDepthVisibility>(views, volume);
    case CarveMethod::kRay:
      break;
  }
  return std::make_unique<RayCastVisibility>(views, volume, options.vis_lookup,
                                             options.order == CarveOrder::kVisiblePixels, workers);
}

bool CarveOptions::IsValid(std::string* reason) const {
  if (resolution < 1 || resolution > 4096) {
    *reason = "resolution must be in [1, 4096], got " + std::to_string(resolution);
    return false;
  }
  if (!std::isfinite(threshold)) {
    *reason = "threshold must be a finite number";
    return false;
  }

  if (!std::isfinite(adaptive_threshold) || adaptive_threshold < 0.0) {
    *reason = "adaptive_threshold must be a finite number >= 0";
    return false;
  }
  if (min_views < 1) {
    *reason = "min_views must be >= 1";
    return false;
  }
  if (batch_voxels < 1 || batch_voxels > 65536) {
    *reason = "batch_voxels must be in [1, 65536], got " + std::to_string(batch_voxels);
    return false;
  }
  if (!(auto_threshold_quantile > 0.0 && auto_threshold_quantile <= 1.0)) {
    *reason = "auto_threshold_quantile must be in (0, 1], got " +
              std::to_string(auto_threshold_quantile);
    return false;
  }
  if (decision == CarveDecision::kReprojection && method != CarveMethod::kRay) {
    *reason = "the reprojection decision needs ray casting (--method ray)";
    return false;
  }
  if (incremental_statistics && method != CarveMethod::kRay) {
    *reason = "incremental statistics need ray casting (--method ray)";
    return false;
  }
  std::vector<int> resolutions;
  if (!LevelResolutions(resolution, lod_levels, &resolutions, reason)) return false;
  if (!(lod_threshold_scale >= 1.0 && lod_threshold_scale <= 10.0)) {
    *reason = "lod_threshold_scale must be in [1, 10], got " + std::to_string(lod_threshold_scale);
    return false;
  }
  if (min_component_voxels < 0) {
    *reason = "min_component_voxels must be >= 0";
    return false;
  }
  if (lod_band < 0 || lod_band > 8) {
    *reason = "lod_band must be in [0, 8], got " + std::to_string(lod_band);
    return false;
  }
  if (!(max_memory_gib > 0.0)) {
    *reason = "max_memory_gib must be > 0";
    return false;
  }
  return true;
}

std::string CarveStatistics::Summary() const {
  std::ostringstream text;
  text.precision(3);
  text << visibility << " carving of a " << dimensions.x() << "x" << dimensions.y() << "x"
       << dimensions.z() << " grid: " << carved << " voxels carved, " << evaluated
       << " evaluated in " << carve_seconds << " s on " << ThreadsText() << " (set-up "
       << setup_seconds << " s), " << final_surface << " surface voxels (" << visible_surface
       << " seen), peak memory "
       << peak_memory_bytes / (1024.0 * 1024.0) << " MiB";
  return text.str();
}

std::string CarveStatistics::ThreadsText() const {
  std::string text = std::to_string(threads) + (threads == 1 ? " thread" : " threads");
  if (threads > 1 && inline_runs > 0 && parallel_runs > 0) {
    const double share = 100.0 * static_cast<double>(inline_runs) / parallel_runs;
    text += " (one alone for " + std::to_string(static_cast<int>(std::lround(share))) +
            "% of the parallel runs: the other cores were busy)";
  }
  return text;
}

BoxCoverage MeasureBoxCoverage(const std::vector<CalibratedView>& views,
                               const Eigen::AlignedBox3d& box,
                               int min_views) {
  BoxCoverage coverage;
  coverage.view_share.assign(views.size(), 0.0);
  constexpr int kSteps = 17;
  std::vector<int> seen_by(kSteps * kSteps * kSteps, 0);
  for (size_t v = 0; v < views.size(); ++v) {
    const CalibratedView& view = views[v];
    int seen = 0;
    for (int i = 0; i < kSteps * kSteps * kSteps; ++i) {
      const Eigen::Vector3d t((i % kSteps + 0.5) / kSteps, ((i / kSteps) % kSteps + 0.5) / kSteps,
                              (i / (kSteps * kSteps) + 0.5) / kSteps);
      const Eigen::Vector3d point = box.min() + box.sizes().cwiseProduct(t);
      if (!(view.Depth(point) > 0.0)) continue;
      const Eigen::Vector2d pixel = view.Project(point);
      if (!(pixel.x() >= 0.0 && pixel.y() >= 0.0 && pixel.x() < view.width &&
            pixel.y() < view.height)) {
        continue;
      }
      const int col = static_cast<int>(pixel.x()), row = static_cast<int>(pixel.y());
      if (!view.valid.empty() && view.valid.at<uint8_t>(row, col) == 0) continue;
      ++seen;
      ++seen_by[i];
    }
    coverage.view_share[v] = static_cast<double>(seen) / seen_by.size();
  }
  int seen_enough = 0;
  for (int count : seen_by) seen_enough += count >= min_views;
  coverage.seen_share = static_cast<double>(seen_enough) / seen_by.size();
  return coverage;
}

bool CheckCarveFits(const std::vector<CalibratedView>& views,
                    const Eigen::AlignedBox3d& box,
                    const CarveOptions& options,
                    std::string* reason) {
  if (!options.IsValid(reason)) return false;
  const bool lists = options.method == CarveMethod::kRay && options.vis_lookup == VisLookup::kRayLists;
  double bytes_per_pixel = lists ? kBytesPerListedRay : kBytesPerRay;
  if (options.method == CarveMethod::kGvc) bytes_per_pixel = kBytesPerItemPixel;
  if (options.method == CarveMethod::kGvcLdi) bytes_per_pixel = kBytesPerLayeredPixel;
  double ray_bytes = 0.0;
  for (const CalibratedView& view : views) {
    ray_bytes += bytes_per_pixel * view.width * view.height;
  }
  const double max_bytes = options.max_memory_gib * 1024.0 * 1024.0 * 1024.0;
  if (ray_bytes > max_bytes) {
    std::ostringstream text;
    text << "the " << (options.method == CarveMethod::kRay ? "rays" : "buffers") << " of "
         << views.size() << " views need " << ray_bytes / (1 << 30)
         << " GiB, above max_memory_gib " << options.max_memory_gib;
    *reason = text.str();
    return false;
  }
  if (!CheckGridFits(box, options.resolution, lists ? kBytesPerListedVoxel : kBytesPerVoxel,
                     max_bytes - ray_bytes, reason)) {
    return false;
  }
  if (options.method == CarveMethod::kRay &&
      !RayImage::KeyBitsFit(VoxelGrid(box, options.resolution).dimensions())) {
    const Eigen::Vector3i n = VoxelGrid(box, options.resolution).dimensions();
    *reason = "rays keep a grid's voxel coordinates in 31 bits; " + std::to_string(n.x()) + "x" +
              std::to_string(n.y()) + "x" + std::to_string(n.z()) +
              " needs more: use a lower resolution";
    return false;
  }
  if (options.method != CarveMethod::kRay &&
      VoxelGrid(box, options.resolution).num_voxels() >= (int64_t{1} << 32) - 1) {
    *reason = CarveMethodToString(options.method) +
              " keeps 32-bit voxel indices: use fewer than 2^32 voxels (a lower resolution)";
    return false;
  }
  return true;
}

IncrementalCarver::IncrementalCarver(const std::vector<CalibratedView>& views,
                                     const Eigen::AlignedBox3d& box,
                                     const CarveOptions& options,
                                     const VisibilityFactory& factory)
    : IncrementalCarver(views, Volume(CheckedGrid(views, box, options)), options, factory) {}

IncrementalCarver::IncrementalCarver(const std::vector<CalibratedView>& views,
                                     Volume start,
                                     const CarveOptions& options,
                                     const VisibilityFactory& factory)
    : views_(views),
      volume_(PreCarved(views, std::move(start), options, &visual_hull_, &free_space_)),
      workers_(static_cast<int>(views.size()),
               options.method == CarveMethod::kRay ? options.num_threads : 1),
      visibility_(factory ? factory(views, volume_)
                          : MakeVisibility(views, volume_, options, &workers_)),
      ray_visibility_(dynamic_cast<RayCastVisibility*>(visibility_.get())),
      test_(options.consistency, options.threshold, options.min_views, options.adaptive_threshold),
      patterns_(options.consistency == ConsistencyMethod::kPatchCorrelation),
      min_coverage_(options.min_coverage),
      min_views_(options.min_views),
      pattern_threshold_(options.pattern_threshold),
      order_(options.order),
      decision_(options.decision),
      threshold_(options.threshold),
      queued_((volume_.grid().num_voxels() + 63) / 64, 0) {
  std::string reason;
  CHECK(options.IsValid(&reason)) << reason;
  for (const CalibratedView& view : views) {
    const cv::Mat usable = view.mask.empty() ? view.valid : (view.valid & view.mask);
    usable_pixels_ += usable.empty() ? static_cast<int64_t>(view.width) * view.height
                                     : cv::countNonZero(usable);
  }
  if (options.protect_surface_points) {
    protected_.assign((volume_.grid().num_voxels() + 63) / 64, 0);
    for (int64_t voxel : SurfacePointVoxels(volume_.grid(), options.surface_points)) {
      protected_[voxel >> 6] |= uint64_t{1} << (voxel & 63);
    }
    known_depth_ = KnownSurfaceDepths(views, volume_.grid(), options.surface_points);
  }
  batched_ = Batched(options) && ray_visibility_ != nullptr && ray_visibility_->ViewParallel();
  batch_voxels_ = batched_ ? options.batch_voxels : 1;
  view_parallel_ = !batched_ && ray_visibility_ != nullptr && ray_visibility_->ViewParallel() &&
                   order_ == CarveOrder::kFifo && workers_.num_groups() > 1 &&
                   workers_.num_groups() <= static_cast<int>(views.size());
  if (view_parallel_ || batched_) groups_.resize(workers_.num_groups());
  if (batched_) {
    view_buffers_.resize(views.size());
    view_outputs_.resize(views.size());
    view_claimed_ = std::make_unique<std::atomic<uint8_t>[]>(views.size());
    claim_order_.resize(views.size());
    std::iota(claim_order_.begin(), claim_order_.end(), 0);
  }
  if (options.incremental_statistics) {
    CHECK(ray_visibility_ != nullptr) << "incremental statistics need ray casting";
    sums_ = std::make_unique<VoxelColourSums>(volume_.grid().num_voxels(),
                                              static_cast<int>(views.size()));
    for (int view = 0; view < static_cast<int>(views.size()); ++view) {
      const RayImage& rays = ray_visibility_->rays(view);
      for (int pixel = 0; pixel < rays.num_pixels(); ++pixel) {
        const int64_t voxel = rays.CurrentVoxel(pixel);
        if (voxel != RayImage::kNoVoxel) {
          sums_->Add(voxel, view, views[view].image.data + 3 * static_cast<size_t>(pixel));
        }
      }
    }
  }
  for (int64_t voxel : volume_.SurfaceVoxels()) Enqueue(voxel);
  max_queue_ = queue_size();
}

void IncrementalCarver::Enqueue(int64_t voxel) {
  uint64_t& word = queued_[voxel >> 6];
  const uint64_t bit = uint64_t{1} << (voxel & 63);
  if (order_ == CarveOrder::kFifo) {
    if (word & bit) return;
    word |= bit;
    queue_.push_back(voxel);
    return;
  }
  // Queued again with its new count; the older entry is skipped when it comes up.
  word |= bit;
  heap_.emplace(visibility_->CountVis(voxel), voxel);
}

bool IncrementalCarver::Pop(int64_t* voxel) {
  while (true) {
    if (order_ == CarveOrder::kFifo) {
      if (queue_.empty()) return false;
      *voxel = queue_.front();
      queue_.pop_front();
    } else {
      if (heap_.empty()) return false;
      *voxel = heap_.top().second;
      heap_.pop();
    }
    uint64_t& word = queued_[*voxel >> 6];
    const uint64_t bit = uint64_t{1} << (*voxel & 63);
    if (!(word & bit)) continue;  // an older entry of a voxel already handed out
    word &= ~bit;
    return true;
  }
}

Consistency IncrementalCarver::Evaluate(int64_t voxel, bool need_vis) {
  if (sums_ != nullptr) {
    vis_ready_ = false;
    if (need_vis) FindVis(voxel, /*gather=*/false);
    sums_->Stats(voxel, &stats_);
  } else if (view_parallel_ && prefetched_ == voxel) {
    vis_ready_ = true;  // found with the last carving's task
  } else {
    FindVis(voxel, /*gather=*/true);
  }
  prefetched_ = -1;
  return Judge(voxel, stats_);
}

Consistency IncrementalCarver::Judge(int64_t voxel, const std::vector<ViewColourStats>& stats) const {
  Consistency consistency = test_.Evaluate(stats);
  if (min_coverage_ > 0.0 && consistency.judged) {
    // Judged only where enough views see most of the voxel: not through a small hole.
    const VoxelGrid& grid = volume_.grid();
    const Eigen::Vector3d centre = grid.Centre(grid.Voxel(voxel));
    int covered = 0;
    for (const ViewColourStats& view_stats : stats) {
      if (view_stats.count == 0) continue;
      const CalibratedView& view = views_[view_stats.view];
      const double depth = view.Depth(centre);
      if (depth <= 0.0) continue;
      const Eigen::Vector3d towards = (view.centre - centre).normalized();
      const double side = 0.5 * (view.K(0, 0) + view.K(1, 1)) * grid.voxel_size() / depth;
      const double area = side * side * towards.cwiseAbs().sum();
      covered += view_stats.count >= min_coverage_ * area;
    }
    if (covered < min_views_) {
      consistency.judged = false;
      consistency.consistent = true;
    }
  }
  if (patterns_ && consistency.judged && consistency.consistent) {
    const PatchCorrelation patches = CorrelatePatches(
        views_, volume_.grid().Centre(volume_.grid().Voxel(voxel)), volume_.grid().voxel_size(),
        stats);
    if (patches.textured) {
      consistency.pattern_error = patches.error();
      consistency.consistent = consistency.pattern_error <= pattern_threshold_;
    }
  }
  return consistency;
}

void IncrementalCarver::FindVis(int64_t voxel, bool gather) {
  if (view_parallel_) {
    RunViewGroups(nullptr, voxel, gather);
  } else {
    vis_.clear();
    visibility_->ComputeVis(voxel, &vis_);
    if (gather) {
      stats_.clear();
      GatherColours(views_, vis_.data(), vis_.data() + vis_.size(), &stats_);
    }
  }
  vis_ready_ = true;
}

void IncrementalCarver::AddArrivals() {
  for (const PixelRef& ref : vis_) {
    const int64_t reached = ray_visibility_->rays(static_cast<int>(ref.view)).CurrentVoxel(
        static_cast<int>(ref.pixel));
    if (reached == RayImage::kNoVoxel) continue;
    sums_->Add(reached, static_cast<int>(ref.view),
               views_[ref.view].image.data + 3 * static_cast<size_t>(ref.pixel));
  }
}

void IncrementalCarver::RunViewGroups(const std::vector<PixelRef>* advance,
                                      int64_t vis_voxel,
                                      bool gather,
                                      bool advance_found) {
  CHECK(!advance_found || (advance == nullptr && vis_voxel >= 0));
  const int num_views = static_cast<int>(views_.size());
  // `advance` is in view order: view v's pixels are [advance_begin_[v], advance_begin_[v + 1]).
  if (advance != nullptr) {
    advance_begin_.assign(num_views + 1, 0);
    for (const PixelRef& ref : *advance) ++advance_begin_[ref.view + 1];
    for (int view = 0; view < num_views; ++view) advance_begin_[view + 1] += advance_begin_[view];
  }
  const Eigen::Vector3i vis_coordinates =
      vis_voxel >= 0 ? volume_.grid().Voxel(vis_voxel) : Eigen::Vector3i::Zero();
  auto task = [&](int group) {
    GroupBuffers& buffers = groups_[group];
    buffers.changed.clear();
    buffers.vis.clear();
    buffers.stats.clear();
    buffers.changed_end.clear();
    buffers.vis_end.clear();
    buffers.stats_end.clear();
    for (int view = group; view < num_views; view += workers_.num_groups()) {
      // Stepping the rays before finding Vis: the Vis found is that after this carving.
      if (advance != nullptr) {
        ray_visibility_->AdvanceRays(advance->data() + advance_begin_[view],
                                     advance->data() + advance_begin_[view + 1], &buffers.changed);
      }
      if (vis_voxel >= 0) {
        const size_t first = buffers.vis.size();
        ray_visibility_->ComputeVisInView(vis_coordinates, view, &buffers.vis);
        if (advance_found) {
          ray_visibility_->AdvanceRays(buffers.vis.data() + first,
                                       buffers.vis.data() + buffers.vis.size(), &buffers.changed);
        }
        if (gather) {
          GatherColours(views_, buffers.vis.data() + first,
                        buffers.vis.data() + buffers.vis.size(), &buffers.stats);
        }
      }
      buffers.changed_end.push_back(buffers.changed.size());
      buffers.vis_end.push_back(buffers.vis.size());
      buffers.stats_end.push_back(buffers.stats.size());
    }
  };
  workers_.Run(task);
  // Merged view by view: exactly what one thread would have produced.
  if (vis_voxel >= 0) {
    vis_.clear();
    if (gather) stats_.clear();
  }
  const int num_groups = workers_.num_groups();
  for (int view = 0; view < num_views; ++view) {
    const GroupBuffers& buffers = groups_[view % num_groups];
    const int k = view / num_groups;  // the view's place in its group
    const auto append = [k](const auto& from, const std::vector<size_t>& ends, auto* to) {
      const size_t begin = k == 0 ? 0 : ends[k - 1];
      to->insert(to->end(), from.begin() + begin, from.begin() + ends[k]);
    };
    append(buffers.changed, buffers.changed_end, &changed_);
    if (vis_voxel >= 0) {
      append(buffers.vis, buffers.vis_end, &vis_);
      if (gather) append(buffers.stats, buffers.stats_end, &stats_);
    }
  }
}

int64_t IncrementalCarver::PeekNextSolid() const {
  if (order_ != CarveOrder::kFifo || queue_.empty()) return -1;
  const int64_t voxel = queue_.front();
  const bool queued = (queued_[voxel >> 6] >> (voxel & 63)) & 1;
  return queued && volume_.IsSolid(voxel) ? voxel : -1;
}

bool IncrementalCarver::BehindKnownSurface(int64_t voxel,
                                           const std::vector<ViewColourStats>& stats) const {
  if (known_depth_.empty()) return false;
  const VoxelGrid& grid = volume_.grid();
  const Eigen::Vector3d centre = grid.Centre(grid.Voxel(voxel));
  for (const ViewColourStats& view_stats : stats) {
    if (view_stats.count == 0) continue;
    const cv::Mat& depths = known_depth_[view_stats.view];
    if (depths.empty()) continue;
    const CalibratedView& view = views_[view_stats.view];
    const Eigen::Vector3d pixel = view.P * centre.homogeneous();
    if (pixel.z() <= 0.0) continue;
    const int col = static_cast<int>(std::floor(pixel.x() / pixel.z()));
    const int row = static_cast<int>(std::floor(pixel.y() / pixel.z()));
    if (col < 0 || row < 0 || col >= depths.cols || row >= depths.rows) continue;
    const float known = depths.at<float>(row, col);
    if (known > 0.0f && pixel.z() > known - kKnownSurfaceMarginVoxels * grid.voxel_size()) {
      return true;
    }
  }
  return false;
}

void IncrementalCarver::FormBatch(Batch* batch) {
  batch->Clear();
  while (static_cast<int>(batch->entries.size()) < batch_voxels_) {
    if (queue_.empty()) {
      // The arrivals still to be queued go behind what was queued: needed only now.
      if (pending_slot_ < 0) break;
      QueuePendingArrivals();
      continue;
    }
    const int64_t voxel = queue_.front();
    queue_.pop_front();
    if (!volume_.IsSolid(voxel)) {
      queued_[voxel >> 6] &= ~(uint64_t{1} << (voxel & 63));
      continue;
    }
    batch->Add(voxel, volume_.grid());
  }
}

void IncrementalCarver::QueuePendingArrivals() {
  if (pending_slot_ < 0) return;
  const int slot = pending_slot_;
  pending_slot_ = -1;
  // Carved voxel by carved voxel, view by view: the same order for any number of groups. Each
  // view's runs are walked alongside, in carved order.
  const int num_views = static_cast<int>(views_.size());
  std::vector<size_t>& next_run = pending_next_run_;
  next_run.assign(num_views, 0);
  if (workers_.num_groups() > 1) {
    // Written by the views' threads; read below a little of every view at a time.
    for (int view = 0; view < num_views; ++view) {
      const ViewOutput& output = view_outputs_[view];
      const uint32_t num_runs = output.num_runs[slot];
      if (num_runs == 0) continue;
      PrefetchForReading(output.runs[slot], num_runs * sizeof(ReachedRun));
      PrefetchForReading(output.reached[slot],
                         output.runs[slot][num_runs - 1].end * sizeof(int64_t));
    }
  }
  for (size_t j = 0; j < pending_carved_; ++j) {
    for (int view = 0; view < num_views; ++view) {
      const ViewOutput& output = view_outputs_[view];
      const ReachedRun* runs = output.runs[slot];
      const size_t run = next_run[view];
      if (run == output.num_runs[slot] || runs[run].j != j) continue;
      next_run[view] = run + 1;
      const int64_t* reached = output.reached[slot];
      const uint32_t first = run == 0 ? 0 : runs[run - 1].end;
      for (uint32_t p = first; p < runs[run].end; ++p) {
        const int64_t voxel = reached[p];
        // A voxel carved since it was reached was queued then and has since been taken from the
        // queue by FormBatch, which found it empty (see StepBatch): not queued again.
        if (volume_.IsSolid(voxel)) Enqueue(voxel);
      }
    }
  }
  pending_carved_ = 0;
}

void IncrementalCarver::RunViewTask(Batch* carving, int carving_slot, Batch* finding,
                                    int finding_slot) {
  auto work = [&](int view) {
    const Clock::time_point start = Clock::now();
    ViewBuffers& buffers = view_buffers_[view];
    if (carving != nullptr) {
      const std::vector<PixelRef>& vis = buffers.vis[carving_slot];
      const std::vector<Span>& spans = buffers.spans[carving_slot];
      std::vector<int64_t>& reached = buffers.reached[carving_slot];
      std::vector<ReachedRun>& runs = buffers.reached_runs[carving_slot];
      if (workers_.num_groups() > 1) {
        // The calling thread read both when it queued the arrivals of the batch last carved
        // from this slot.
        PrefetchForWriting(reached.data(), reached.size() * sizeof(int64_t));
        PrefetchForWriting(runs.data(), runs.size() * sizeof(ReachedRun));
      }
      reached.clear();
      runs.clear();
      for (size_t j = 0; j < batch_carved_.size(); ++j) {
        const int k = batch_carved_[j];
        if (spans[k].begin == spans[k].end) continue;  // most views see none of a voxel
        const size_t begin = reached.size();
        ray_visibility_->AdvanceRaysFrom(carving->coordinates[k],
                                         vis.data() + spans[k].begin, vis.data() + spans[k].end,
                                         &reached);
        const size_t kept = KeepFirstOccurrences(reached.data() + begin, reached.size() - begin);
        reached.resize(begin + kept);
        if (kept > 0) {
          runs.push_back({static_cast<uint32_t>(j), static_cast<uint32_t>(begin + kept)});
        }
      }
      ViewOutput& output = view_outputs_[view];
      output.reached[carving_slot] = reached.data();
      output.runs[carving_slot] = runs.data();
      output.num_runs[carving_slot] = static_cast<uint32_t>(runs.size());
    }
    if (finding != nullptr) {
      std::vector<PixelRef>& vis = buffers.vis[finding_slot];
      std::vector<Span>& spans = buffers.spans[finding_slot];
      std::vector<BatchHit>& hits = buffers.hits[finding_slot];
      if (workers_.num_groups() > 1) {
        // The calling thread read them when it judged the batch last found in this slot.
        PrefetchForWriting(hits.data(), hits.size() * sizeof(BatchHit));
      }
      vis.clear();
      hits.clear();
      const int num_entries = static_cast<int>(finding->entries.size());
      spans.assign(num_entries, Span{});  // empty, unless the view sees the voxel
      // The footprints first, so that the rays and photo rows of the voxels a few ahead can be
      // fetched while a voxel's are scanned: the scans wait on memory more than they compute.
      // Most views see none of a voxel (no ray of theirs ends in it: an empty footprint); only
      // the others are scanned, and fetched ahead.
      std::vector<Footprint>& footprints = buffers.footprints;
      std::vector<int>& seen = buffers.seen;
      footprints.resize(num_entries);
      seen.clear();
      for (int k = 0; k < num_entries; ++k) {
        footprints[k] = ray_visibility_->VisFootprint(finding->coordinates[k], view);
        if (!footprints[k].empty()) seen.push_back(k);
      }
      const cv::Mat& photo = views_[view].image;
      const uint8_t* image = photo.data;
      const int num_seen = static_cast<int>(seen.size());
      for (int i = 0; i < num_seen; ++i) {
        if (i + kPrefetchAhead < num_seen) {
          const Footprint& ahead = footprints[seen[i + kPrefetchAhead]];
          ray_visibility_->PrefetchRays(ahead, view);
          for (int row = ahead.row_min; row <= ahead.row_max; ++row) {
            const uint8_t* line = photo.ptr<uint8_t>(row);
            __builtin_prefetch(line + 3 * ahead.col_min);
            __builtin_prefetch(line + 3 * ahead.col_max + 2);
          }
        }
        const int k = seen[i];
        Span& span = spans[k];
        span.begin = static_cast<uint32_t>(vis.size());
        ray_visibility_->AppendVis(footprints[k], finding->coordinates[k], view, &vis);
        span.end = static_cast<uint32_t>(vis.size());
        if (span.end == span.begin) continue;
        for (uint32_t first = span.begin; first < span.end; first += kMaxHitPixels) {
          const uint32_t last = std::min(span.end, first + kMaxHitPixels);
          uint32_t sum[3] = {0, 0, 0}, sum_squares[3] = {0, 0, 0};
          for (uint32_t p = first; p < last; ++p) {
            const uint8_t* rgb = image + 3 * static_cast<size_t>(vis[p].pixel);
            for (int c = 0; c < 3; ++c) {
              sum[c] += rgb[c];
              sum_squares[c] += uint32_t{rgb[c]} * rgb[c];
            }
          }
          BatchHit& hit = hits.emplace_back();
          hit.k = k;
          hit.count = last - first;
          for (int c = 0; c < 3; ++c) {
            hit.sum[c] = sum[c];
            hit.sum_squares[c] = sum_squares[c];
          }
        }
      }
      ViewOutput& output = view_outputs_[view];
      output.hits[finding_slot] = hits.data();
      output.num_hits[finding_slot] = static_cast<uint32_t>(hits.size());
    }
    buffers.nanoseconds += ElapsedNanoseconds(start);
  };
  // The calling thread queues the last task's arrivals (in the other slot) while the others
  // take its views.
  if (pending_slot_ == carving_slot) QueuePendingArrivals();
  ClaimViews(workers_, claim_order_, view_claimed_.get(), work,
             [this](int group) {
               if (group == 0) QueuePendingArrivals();
             });
  if (++tasks_since_sort_ >= kSortTasks) SortViewsByCost();
}

void IncrementalCarver::SortViewsByCost() {
  tasks_since_sort_ = 0;
  std::stable_sort(claim_order_.begin(), claim_order_.end(), [this](int a, int b) {
    return view_buffers_[a].nanoseconds > view_buffers_[b].nanoseconds;
  });
  for (ViewBuffers& buffers : view_buffers_) buffers.nanoseconds = 0;
}

void IncrementalCarver::JudgeEntries(Batch* batch, int slot, bool colouring) {
  const int num_views = static_cast<int>(views_.size());
  // Judges entries [first, last). Their sums are first gathered view by view (each view's hits
  // are in batch order, a voxel's consecutive), into each entry's views in view order: read so,
  // each view's hits are one stream that the processor fetches ahead, where walking the entries
  // and for each every view's next hit waited on memory (22% of the judging's time at one
  // instruction) and branched unpredictably (a view sees about a third of the voxels).
  auto judge = [&](int first, int last, int group) {
    GroupBuffers& own = groups_[group];
    std::vector<ViewColourStats>& stats = own.stats;
    std::vector<ViewColourStats>& view_sums = own.view_sums;
    std::vector<uint32_t>& begin = own.view_sums_begin;
    std::vector<uint32_t>& count = own.view_sums_count;
    const int num_entries = last - first;
    auto hits_from = [&](int view) {
      const ViewOutput& output = view_outputs_[view];
      const BatchHit* end = output.hits[slot] + output.num_hits[slot];
      const BatchHit* hit =
          first == 0 ? output.hits[slot]
                     : std::lower_bound(output.hits[slot], end, first,
                                        [](const BatchHit& h, int key) { return h.k < key; });
      return std::make_pair(hit, end);
    };
    // The views of each entry (a voxel's hits in one view are consecutive)...
    count.assign(num_entries + 1, 0);
    if (first == 0 && workers_.num_groups() > 1) {
      // Written by the views' threads: fetched at once rather than a view's stream at a time.
      for (int view = 0; view < num_views; ++view) {
        const ViewOutput& output = view_outputs_[view];
        PrefetchForReading(output.hits[slot], output.num_hits[slot] * sizeof(BatchHit));
      }
    }
    for (int view = 0; view < num_views; ++view) {
      auto [hit, end] = hits_from(view);
      for (int previous = -1; hit != end && hit->k < last; ++hit) {
        count[hit->k - first] += hit->k != previous;
        previous = hit->k;
      }
    }
    begin.resize(num_entries + 1);
    uint32_t total = 0;
    for (int i = 0; i <= num_entries; ++i) {
      begin[i] = total;
      total += count[i];
      count[i] = 0;
    }
    // ...then their sums, view by view.
    // A voxel's hits in a view (more than one where it has more than kMaxHitPixels pixels there)
    // are summed as integers, exactly, and written once.
    view_sums.resize(total);
    for (int view = 0; view < num_views; ++view) {
      auto [hit, end] = hits_from(view);
      while (hit != end && hit->k < last) {
        const int k = hit->k;
        uint64_t pixels = 0, sum[3] = {0, 0, 0}, sum_squares[3] = {0, 0, 0};
        for (; hit != end && hit->k == k; ++hit) {
          pixels += hit->count;
          for (int c = 0; c < 3; ++c) {
            sum[c] += hit->sum[c];
            sum_squares[c] += hit->sum_squares[c];
          }
        }
        const int i = k - first;
        ViewColourStats& view_stats = view_sums[begin[i] + count[i]++];
        view_stats.view = view;
        view_stats.count = static_cast<int>(pixels);
        view_stats.sum = Eigen::Vector3d(static_cast<double>(sum[0]), static_cast<double>(sum[1]),
                                         static_cast<double>(sum[2]));
        view_stats.sum_squares =
            Eigen::Vector3d(static_cast<double>(sum_squares[0]),
                            static_cast<double>(sum_squares[1]),
                            static_cast<double>(sum_squares[2]));
      }
    }
    for (int k = first; k < last; ++k) {
      const int i = k - first;
      stats.assign(view_sums.begin() + begin[i], view_sums.begin() + begin[i + 1]);
      BatchEntry& entry = batch->entries[k];
      entry.num_pixels = 0;
      for (const ViewColourStats& view_stats : stats) entry.num_pixels += view_stats.count;
      entry.consistency = Judge(entry.voxel, stats);
      entry.carve = !entry.consistency.consistent;
      entry.kept_protected = false;
      if (entry.carve && (IsProtected(entry.voxel) || BehindKnownSurface(entry.voxel, stats))) {
        entry.carve = false;
        entry.kept_protected = true;
      }
      if (colouring) {
        // The pixels' distance to the voxel's colour, summed view by view in pixel order.
        double error = 0.0;
        for (int view = 0; view < num_views; ++view) {
          const ViewBuffers& buffers = view_buffers_[view];
          const Span& span = buffers.spans[slot][k];
          for (uint32_t p = span.begin; p < span.end; ++p) {
            error += (PixelColour(buffers.vis[slot][p]) - entry.consistency.colour).norm();
          }
        }
        entry.reprojection_error = error;
      }
    }
  };
  const int count = static_cast<int>(batch->entries.size());
  if (!colouring && !patterns_) {
    judge(0, count, 0);
    return;
  }
  const int chunks = (count + kClaimChunk - 1) / kClaimChunk;
  ClaimItems(workers_, chunks, 1, [&](int chunk, int group) {
    judge(chunk * kClaimChunk, std::min(count, (chunk + 1) * kClaimChunk), group);
  });
}

void IncrementalCarver::ReturnPendingBatch() {
  QueuePendingArrivals();
  if (!batch_found_) return;
  // The queued bits are still set: the voxels go back to the front, in their order.
  const std::vector<BatchEntry>& entries = batches_[current_].entries;
  for (auto entry = entries.rbegin(); entry != entries.rend(); ++entry) {
    queue_.push_front(entry->voxel);
  }
  batches_[current_].Clear();
  batch_found_ = false;
}

bool IncrementalCarver::StepBatch() {
  Batch& current = batches_[current_];
  if (!batch_found_) {
    FormBatch(&current);
    if (current.entries.empty()) return false;
    RunViewTask(nullptr, 0, &current, current_);
  }
  if (workers_.num_groups() > 1) {
    // The next batch's coordinates are written after the judging, and the other threads read
    // them last (see PrefetchForWriting).
    const std::vector<Eigen::Vector3i>& next_coordinates = batches_[1 - current_].coordinates;
    PrefetchForWriting(next_coordinates.data(),
                       next_coordinates.capacity() * sizeof(Eigen::Vector3i));
  }
  // Every voxel judged against the rays as they stood before any of the batch was carved.
  JudgeEntries(&current, current_, /*colouring=*/false);
  evaluated_ += static_cast<int64_t>(current.entries.size());
  batch_carved_.clear();
  for (int k = 0; k < static_cast<int>(current.entries.size()); ++k) {
    const BatchEntry& entry = current.entries[k];
    protected_kept_ += entry.kept_protected;
    if (entry.carve) batch_carved_.push_back(k);
  }
  // The voxels a carve exposes are queued as rays reach them (QueuePendingArrivals), not here.
  for (int k : batch_carved_) volume_.Carve(current.entries[k].voxel, nullptr);
  carved_ += static_cast<int64_t>(batch_carved_.size());
  // The rays that ended in the carved voxels step on (through all of them), and the next batch's
  // Vis is found after them, view by view in one task; in it the calling thread queues the
  // voxels the last task's rays reached (QueuePendingArrivals). The queue is as if they had been
  // queued before this batch was judged, as the FIFO order has it: the next batch comes from the
  // queue's front, and they go to its back (FormBatch queues them first where the queue runs
  // out); this batch's voxels keep their queued bits until then, so that they are not queued
  // again (judged with the rays as the last carve left them); a voxel carved since it was reached
  // was queued then and, taken by FormBatch, skipped (QueuePendingArrivals checks).
  const int next_slot = 1 - current_;
  Batch& next = batches_[next_slot];
  FormBatch(&next);
  if (!batch_carved_.empty() || !next.entries.empty()) {
    RunViewTask(batch_carved_.empty() ? nullptr : &current, current_,
                next.entries.empty() ? nullptr : &next, next_slot);
  } else {
    QueuePendingArrivals();
  }
  max_queue_ = std::max(max_queue_, queue_size() + next.entries.size());
  for (const BatchEntry& entry : current.entries) {
    queued_[entry.voxel >> 6] &= ~(uint64_t{1} << (entry.voxel & 63));
  }
  if (!batch_carved_.empty()) {
    pending_slot_ = current_;
    pending_carved_ = batch_carved_.size();
  }
  current_ = next_slot;
  batch_found_ = !next.entries.empty();
  return true;
}

bool IncrementalCarver::Step() {
  if (batched_) return StepBatch();
  int64_t voxel = 0;
  if (!Pop(&voxel)) {
    if (!visibility_->StartPass()) return false;
    ++passes_;
    for (int64_t surface : volume_.SurfaceVoxels()) Enqueue(surface);
    max_queue_ = std::max(max_queue_, queue_size());
    if (!Pop(&voxel)) return false;
  }
  if (!volume_.IsSolid(voxel)) return true;
  ++evaluated_;
  // Vis(V) is needed to judge V only by the reprojection decision, or without incremental
  // statistics (which gather from it).
  const Consistency consistency = Evaluate(voxel, decision_ == CarveDecision::kReprojection);
  // The threshold carves what is inconsistent; the reprojection decision also carves consistent
  // voxels whose pixels the voxels behind them explain better (floaters consistent by chance).
  if (consistency.consistent &&
      (decision_ == CarveDecision::kThreshold || !consistency.judged ||
       ReprojectionChange(consistency.colour) >= 0.0)) {
    return true;
  }
  if (IsProtected(voxel) || BehindKnownSurface(voxel, stats_)) {
    ++protected_kept_;
    return true;
  }
  exposed_.clear();
  changed_.clear();
  volume_.Carve(voxel, &exposed_);
  if (sums_ != nullptr) sums_->Release(voxel);
  if (view_parallel_ && sums_ != nullptr && !vis_ready_) {
    // One task finds Vis(V) and steps its rays.
    RunViewGroups(nullptr, voxel, /*gather=*/false, /*advance_found=*/true);
  } else if (view_parallel_ && sums_ != nullptr) {
    RunViewGroups(&vis_, -1);
  } else if (view_parallel_) {
    // One task steps the rays and finds Vis of the voxel evaluated next (fifo: the front of
    // the queue, which the voxels queued below go behind), saving a second hand-over.
    prefetched_ = PeekNextSolid();
    RunViewGroups(&vis_, prefetched_);
  } else {
    if (!vis_ready_) FindVis(voxel, /*gather=*/false);
    visibility_->UpdateAfterCarve(voxel, vis_, exposed_, &changed_);
  }
  if (sums_ != nullptr) AddArrivals();
  if (order_ != CarveOrder::kFifo) {
    // One entry per voxel, with its count after every ray has arrived.
    std::sort(changed_.begin(), changed_.end());
    changed_.erase(std::unique(changed_.begin(), changed_.end()), changed_.end());
  }
  for (int64_t next : changed_) Enqueue(next);
  ++carved_;
  max_queue_ = std::max(max_queue_, queue_size());
  return true;
}

void IncrementalCarver::CarveAndQueue(int64_t voxel) {
  ReturnPendingBatch();
  prefetched_ = -1;
  vis_.clear();
  visibility_->ComputeVis(voxel, &vis_);
  exposed_.clear();
  changed_.clear();
  volume_.Carve(voxel, &exposed_);
  if (sums_ != nullptr) sums_->Release(voxel);
  visibility_->UpdateAfterCarve(voxel, vis_, exposed_, &changed_);
  if (sums_ != nullptr) AddArrivals();
  vis_ready_ = false;
  for (int64_t next : changed_) Enqueue(next);
}

namespace {

// Calls visit(voxels) for each 26-connected component of `volume`'s solid voxels (in the order of
// their first voxel's index; each component's voxels in breadth-first order from it).
template <typename Visit>
void ForEachSolidComponent(const Volume& volume, Visit visit) {
  const VoxelGrid& grid = volume.grid();
  const Eigen::Vector3i& n = grid.dimensions();
  std::vector<uint64_t> seen((grid.num_voxels() + 63) / 64, 0);
  const auto mark = [&seen](int64_t i) {
    const bool was = (seen[i >> 6] >> (i & 63)) & 1;
    seen[i >> 6] |= uint64_t{1} << (i & 63);
    return !was;
  };
  std::vector<int64_t> component;
  for (int64_t start = 0; start < grid.num_voxels(); ++start) {
    if (!volume.IsSolid(start) || !mark(start)) continue;
    component.assign(1, start);
    for (size_t k = 0; k < component.size(); ++k) {
      const Eigen::Vector3i voxel = grid.Voxel(component[k]);
      for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const Eigen::Vector3i next = voxel + Eigen::Vector3i(dx, dy, dz);
            if ((next.array() < 0).any() || (next.array() >= n.array()).any()) continue;
            const int64_t index = grid.Index(next);
            if (volume.IsSolid(index) && mark(index)) component.push_back(index);
          }
        }
      }
    }
    visit(component);
  }
}

}  // namespace

int64_t IncrementalCarver::RemoveSmallComponents(int64_t min_voxels) {
  std::vector<int64_t> small;
  ForEachSolidComponent(volume_, [&](const std::vector<int64_t>& component) {
    if (static_cast<int64_t>(component.size()) < min_voxels) {
      small.insert(small.end(), component.begin(), component.end());
    }
  });
  for (int64_t voxel : small) CarveAndQueue(voxel);
  return static_cast<int64_t>(small.size());
}

int64_t IncrementalCarver::RemoveUnsupportedComponents(const std::vector<SurfacePoint>& points,
                                                       double min_expected,
                                                       int64_t* components,
                                                       double* largest_expected) {
  const VoxelGrid& grid = volume_.grid();
  // Which points lie within one voxel of each voxel (only voxels near a point are listed).
  std::unordered_map<int64_t, std::vector<int>> points_near;
  for (size_t p = 0; p < points.size(); ++p) {
    const Eigen::Vector3i centre = grid.VoxelOf(points[p].xyz);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3i voxel = centre + Eigen::Vector3i(dx, dy, dz);
          if (grid.Contains(voxel)) points_near[grid.Index(voxel)].push_back(static_cast<int>(p));
        }
      }
    }
  }
  // First pass: each component's surface voxels and the points beside it.
  struct Component {
    int64_t surface = 0;
    int64_t supported = 0;  // points claimed (each by the first component found beside it)
  };
  std::vector<Component> found;
  std::vector<uint8_t> claimed(points.size(), 0);
  ForEachSolidComponent(volume_, [&](const std::vector<int64_t>& voxels) {
    Component component;
    for (int64_t index : voxels) {
      component.surface += volume_.IsSurface(index);
      const auto near = points_near.find(index);
      if (near == points_near.end()) continue;
      for (int p : near->second) {
        if (claimed[p]) continue;
        claimed[p] = 1;
        ++component.supported;
      }
    }
    found.push_back(component);
  });
  int64_t supported = 0, supported_surface = 0, largest = 0;
  for (const Component& c : found) {
    largest = std::max(largest, c.surface);
    if (c.supported == 0) continue;
    supported += c.supported;
    supported_surface += c.surface;
  }
  std::vector<uint8_t> floater(found.size(), 0);
  int64_t removed = 0;
  double most_expected = 0.0;
  if (supported_surface > 0) {
    const double density = static_cast<double>(supported) / supported_surface;
    for (size_t k = 0; k < found.size(); ++k) {
      const Component& c = found[k];
      const double expected = density * c.surface;
      if (c.supported > 0 || expected < min_expected || 4 * c.surface >= largest) continue;
      floater[k] = 1;
      ++removed;
      most_expected = std::max(most_expected, expected);
    }
  }
  // Second pass (the same components in the same order): the floaters' voxels, then carved.
  std::vector<int64_t> carve;
  if (removed > 0) {
    size_t k = 0;
    ForEachSolidComponent(volume_, [&](const std::vector<int64_t>& voxels) {
      if (floater[k++]) carve.insert(carve.end(), voxels.begin(), voxels.end());
    });
  }
  for (int64_t voxel : carve) CarveAndQueue(voxel);
  if (components != nullptr) *components = removed;
  if (largest_expected != nullptr) *largest_expected = most_expected;
  return static_cast<int64_t>(carve.size());
}

std::vector<ColouredVoxel> IncrementalCarver::ColourSurface() {
  std::vector<ColouredVoxel> surface;
  double error = 0.0;
  int64_t explained = 0;
  auto add = [&surface](int64_t voxel, const Consistency& consistency) {
    ColouredVoxel coloured;
    coloured.index = voxel;
    coloured.colour = consistency.colour.cast<float>();
    coloured.num_views = consistency.num_views;
    coloured.num_pixels = consistency.num_pixels;
    surface.push_back(coloured);
  };
  if (batched_) {
    // Judged on every thread, a chunk of the surface at a time; summed in surface order.
    ReturnPendingBatch();
    const std::vector<int64_t> voxels = volume_.SurfaceVoxels();
    constexpr size_t kChunk = 4096;
    Batch& chunk = batches_[current_];
    for (size_t first = 0; first < voxels.size(); first += kChunk) {
      chunk.Clear();
      for (size_t i = first; i < std::min(voxels.size(), first + kChunk); ++i) {
        chunk.Add(voxels[i], volume_.grid());
      }
      RunViewTask(nullptr, 0, &chunk, current_);
      JudgeEntries(&chunk, current_, /*colouring=*/true);
      for (const BatchEntry& entry : chunk.entries) {
        add(entry.voxel, entry.consistency);
        error += entry.reprojection_error;
        explained += entry.num_pixels;
      }
    }
    chunk.Clear();
  } else {
    for (int64_t voxel : volume_.SurfaceVoxels()) {
      const Consistency consistency = Evaluate(voxel);
      add(voxel, consistency);
      for (const PixelRef& ref : vis_) error += (PixelColour(ref) - consistency.colour).norm();
      explained += static_cast<int64_t>(vis_.size());
    }
  }
  error += threshold_ * static_cast<double>(std::max<int64_t>(0, usable_pixels_ - explained));
  surface_reprojection_error_ = usable_pixels_ == 0 ? 0.0 : error / usable_pixels_;
  return surface;
}

double IncrementalCarver::ReprojectionChange(const Eigen::Vector3d& colour) {
  RayCastVisibility* rays = ray_visibility_;
  CHECK(rays != nullptr) << "the reprojection decision needs ray casting";
  double change = 0.0;
  arrivals_.clear();
  for (size_t i = 0; i < vis_.size(); ++i) {
    change -= (PixelColour(vis_[i]) - colour).norm();
    const int64_t next =
        rays->rays(vis_[i].view).PeekBeyondCurrent(static_cast<int>(vis_[i].pixel), volume_);
    if (next == RayImage::kNoVoxel) {
      change += threshold_;  // the pixel would be explained by nothing
    } else {
      arrivals_.emplace_back(next, static_cast<int>(i));
    }
  }
  std::sort(arrivals_.begin(), arrivals_.end());
  for (size_t begin = 0; begin < arrivals_.size();) {
    size_t end = begin;
    while (end < arrivals_.size() && arrivals_[end].first == arrivals_[begin].first) ++end;
    next_vis_.clear();
    visibility_->ComputeVis(arrivals_[begin].first, &next_vis_);
    Eigen::Vector3d old_sum = Eigen::Vector3d::Zero(), new_sum;
    for (const PixelRef& ref : next_vis_) old_sum += PixelColour(ref);
    new_sum = old_sum;
    for (size_t k = begin; k < end; ++k) new_sum += PixelColour(vis_[arrivals_[k].second]);
    const Eigen::Vector3d new_mean = new_sum / static_cast<double>(next_vis_.size() + end - begin);
    if (!next_vis_.empty()) {
      const Eigen::Vector3d old_mean = old_sum / static_cast<double>(next_vis_.size());
      for (const PixelRef& ref : next_vis_) {
        const Eigen::Vector3d c = PixelColour(ref);
        change += (c - new_mean).norm() - (c - old_mean).norm();
      }
    }
    for (size_t k = begin; k < end; ++k) {
      change += (PixelColour(vis_[arrivals_[k].second]) - new_mean).norm();
    }
    begin = end;
  }
  return change;
}

double IncrementalCarver::MeanReprojectionError() {
  ColourSurface();
  return surface_reprojection_error_;
}

size_t IncrementalCarver::MemoryBytes() const {
  const size_t entry = order_ == CarveOrder::kFifo ? sizeof(int64_t) : 2 * sizeof(int64_t);
  return volume_.MemoryBytes() + visibility_->MemoryBytes() + queued_.size() * sizeof(uint64_t) +
         max_queue_ * entry + (sums_ != nullptr ? sums_->MemoryBytes() : 0);
}

CarveResult CarveVolume(const std::vector<CalibratedView>& views,
                        const Eigen::AlignedBox3d& box,
                        const CarveOptions& options,
                        const std::function<void(const CarveProgress&)>& progress,
                        double progress_interval_seconds) {
  std::string reason;
  CHECK(CheckCarveFits(views, box, options, &reason)) << reason;
  std::vector<int> resolutions;
  CHECK(LevelResolutions(options.resolution, options.lod_levels, &resolutions, &reason)) << reason;
  const int num_levels = static_cast<int>(resolutions.size());
  const VoxelGrid final_grid(box, options.resolution);

  CarveStatistics statistics;
  Clock::time_point start;  // when the first level's carving began
  double next_report = progress_interval_seconds;
  double next_sample = 0.0;
  int64_t hull_carved = 0;  // the first level's visual hull, in final voxels
  std::unique_ptr<IncrementalCarver> carver;
  std::vector<CalibratedView> reduced_views;  // the photos of a coarse level, when reduced
  auto add_worker_times = [&statistics](const IncrementalCarver& level_carver) {
    const ViewWorkers::Times times = level_carver.worker_times();
    statistics.parallel_seconds += times.wall_seconds;
    statistics.parallel_runs += times.runs;
    statistics.inline_runs += times.inline_runs;
    if (statistics.thread_work_seconds.size() < times.busy_seconds.size()) {
      statistics.thread_work_seconds.resize(times.busy_seconds.size(), 0.0);
    }
    for (size_t t = 0; t < times.busy_seconds.size(); ++t) {
      statistics.thread_work_seconds[t] += times.busy_seconds[t];
    }
  };
  for (int level = 0; level < num_levels; ++level) {
    const Clock::time_point level_start = Clock::now();
    CarveOptions level_options = options;
    level_options.resolution = resolutions[level];
    level_options.lod_levels = 1;
    level_options.threshold =
        options.threshold * std::pow(options.lod_threshold_scale, num_levels - 1 - level);
    const int factor = options.lod_reduce_images ? ImageFactor(views, resolutions[level],
                                                               options.resolution)
                                                 : 1;
    std::unique_ptr<Volume> start_volume;
    if (level > 0) {
      start_volume = std::make_unique<Volume>(
          RefineVolume(carver->volume(), VoxelGrid(box, resolutions[level]), options.lod_band));
      carver.reset();  // the coarse level's rays and queue go before the fine level's come
    }
    reduced_views.clear();
    if (factor > 1) {
      reduced_views.resize(views.size());
      for (size_t v = 0; v < views.size(); ++v) reduced_views[v] = ReduceView(views[v], factor);
    }
    const std::vector<CalibratedView>& level_views = factor > 1 ? reduced_views : views;
    LevelStatistics level_statistics;
    const bool auto_pattern = options.consistency == ConsistencyMethod::kPatchCorrelation &&
                              (options.auto_threshold || options.auto_pattern_threshold);
    if (options.auto_threshold || auto_pattern) {
      level_statistics.estimate = EstimateThreshold(
          level_views, VoxelGrid(box, resolutions[level]), options.surface_points,
          options.consistency, options.min_views,
          std::any_of(level_views.begin(), level_views.end(),
                      [](const CalibratedView& view) { return !view.mask.empty(); }),
          options.auto_threshold_quantile,
          level_options.threshold, options.pattern_threshold);
      level_statistics.threshold_from_data =
          level_statistics.estimate.points_judged >= kMinThresholdPoints;
      if (options.auto_threshold) level_options.threshold = level_statistics.estimate.threshold;
      if (auto_pattern) {
        level_options.pattern_threshold = level_statistics.estimate.pattern_threshold;
      }
    }
    if (level == 0) {
      carver = std::make_unique<IncrementalCarver>(level_views, box, level_options);
    } else {
      carver = std::make_unique<IncrementalCarver>(level_views, std::move(*start_volume),
                                                   level_options);
    }
    // A voxel of this level holds `scale` final voxels (up to the grid's edge).
    const int64_t scale = int64_t{1} << (3 * (num_levels - 1 - level));
    level_statistics.resolution = resolutions[level];
    level_statistics.image_factor = factor;
    level_statistics.threshold = level_options.threshold;
    level_statistics.pattern_threshold = level_options.pattern_threshold;
    level_statistics.dimensions = carver->volume().grid().dimensions();
    level_statistics.start_solid = carver->volume().num_solid();
    level_statistics.setup_seconds = SecondsSince(level_start);
    if (level == 0) {
      statistics.visibility = carver->visibility().Name();
      if (options.method == CarveMethod::kRay) {
        statistics.visibility += " (" + VisLookupToString(options.vis_lookup) + ")";
      }
      statistics.initial_surface = carver->volume().num_surface();
      statistics.views_with_masks = carver->visual_hull().views_with_masks;
      statistics.visual_hull_carved = carver->visual_hull().carved;
      statistics.visual_hull_seconds = carver->visual_hull().seconds;
      statistics.free_space_level0_carved = carver->free_space().carved;
      statistics.setup_seconds = SecondsSince(level_start);
      // The curve leaves out what the visual hull carved; the sparse points' sight lines are in
      // its first value.
      hull_carved = std::min(final_grid.num_voxels(), carver->visual_hull().carved * scale);
      if (options.decision == CarveDecision::kReprojection) {
        statistics.reprojection_error_before = carver->MeanReprojectionError();
      }
      start = Clock::now();
    }
    auto sample = [&](double seconds) {
      const int64_t removed = std::max<int64_t>(
          0, final_grid.num_voxels() - std::min(final_grid.num_voxels(),
                                                carver->volume().num_solid() * scale));
      statistics.curve.push_back({seconds, std::max<int64_t>(0, removed - hull_carved),
                                  statistics.evaluated + carver->evaluated()});
    };
    sample(SecondsSince(start));
    for (int64_t next_check = 1024; carver->Step();) {
      if (carver->evaluated() < next_check) continue;
      next_check = carver->evaluated() + 1024;
      const double seconds = SecondsSince(start);
      if (seconds >= next_sample) {
        sample(seconds);
        next_sample = seconds + 0.05;
      }
      if (progress && seconds >= next_report) {
        progress({level, num_levels, statistics.evaluated + carver->evaluated(), carver->carved(),
                  static_cast<int64_t>(carver->queue_size()), seconds});
        next_report = seconds + progress_interval_seconds;
      }
    }
    // The final level: specks left in empty space go, and carving carries on behind them.
    for (int round = 0; level + 1 == num_levels && options.min_component_voxels > 1 && round < 4;
         ++round) {
      const int64_t removed = carver->RemoveSmallComponents(options.min_component_voxels);
      if (removed == 0) break;
      statistics.component_carved += removed;
      while (carver->Step()) {
      }
    }
    if (level + 1 == num_levels && options.unsupported_component_points > 0.0 &&
        !options.surface_points.empty()) {
      int64_t components = 0;
      double expected = 0.0;
      const int64_t removed = carver->RemoveUnsupportedComponents(
          options.surface_points, options.unsupported_component_points, &components, &expected);
      if (removed > 0) {
        statistics.unsupported_components = components;
        statistics.unsupported_component_carved = removed;
        statistics.unsupported_largest_expected = expected;
        while (carver->Step()) {
        }
      }
    }
    sample(SecondsSince(start));
    level_statistics.carved =
        carver->carved() + carver->visual_hull().carved + carver->free_space().carved;
    level_statistics.free_space_carved = carver->free_space().carved;
    statistics.free_space_carved += carver->free_space().carved;
    statistics.free_space_sight_lines = carver->free_space().sight_lines;
    statistics.free_space_seconds += carver->free_space().seconds;
    level_statistics.evaluated = carver->evaluated();
    level_statistics.protected_kept = carver->protected_kept();
    level_statistics.final_solid = carver->volume().num_solid();
    level_statistics.seconds = SecondsSince(level_start);
    statistics.levels.push_back(level_statistics);
    statistics.evaluated += carver->evaluated();
    statistics.passes = std::max(statistics.passes, carver->passes());
    statistics.threads = carver->threads();
    statistics.peak_memory_bytes = std::max(statistics.peak_memory_bytes, carver->MemoryBytes());
    if (level + 1 < num_levels) add_worker_times(*carver);
  }
  if (options.repair_silhouettes && statistics.views_with_masks > 0) {
    Volume repaired = carver->volume();
    statistics.silhouette_repair = RepairSilhouettes(views, &repaired, options.num_threads);
    if (statistics.silhouette_repair.restored_voxels > 0) {
      // The restored voxels are final: a carver over the repaired volume only colours it.
      CarveOptions colouring = options;
      colouring.lod_levels = 1;
      colouring.visual_hull = false;
      colouring.free_space_margin_voxels = 0.0;
      colouring.protect_surface_points = false;
      colouring.min_component_voxels = 0;
      colouring.unsupported_component_points = 0.0;
      statistics.peak_memory_bytes = std::max(statistics.peak_memory_bytes, carver->MemoryBytes());
      add_worker_times(*carver);
      carver.reset();
      carver = std::make_unique<IncrementalCarver>(views, std::move(repaired), colouring);
    }
  }
  statistics.carve_seconds = SecondsSince(start);
  statistics.dimensions = carver->volume().grid().dimensions();
  statistics.voxel_size = carver->volume().grid().voxel_size();
  statistics.num_voxels = carver->volume().grid().num_voxels();
  statistics.carved = statistics.num_voxels - carver->volume().num_solid();

  const Clock::time_point colour_start = Clock::now();
  CarveResult result{carver->volume().grid()};
  result.surface = carver->ColourSurface();
  statistics.reprojection_error_after = carver->surface_reprojection_error();
  for (const ColouredVoxel& voxel : result.surface) {
    if (voxel.num_pixels > 0) ++statistics.visible_surface;
  }
  statistics.colour_seconds = SecondsSince(colour_start);
  add_worker_times(*carver);
  statistics.final_surface = carver->volume().num_surface();
  statistics.final_solid = carver->volume().num_solid();
  result.volume = std::move(*carver->mutable_volume());
  result.statistics = std::move(statistics);
  if (progress) {
    progress({num_levels - 1, num_levels, result.statistics.evaluated, result.statistics.carved,
              0, result.statistics.carve_seconds});
  }
  return result;
}

}  // namespace raycarve
