#include "carve/incremental_carver.h"

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


#include "carve/carver_internal.h"
#include "carve/known_surface.h"

namespace raycarve {

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


namespace {

// Whether `options` carve in batches (CarveOptions::batch_voxels), given ray casting that finds
// Vis by footprints.
bool Batched(const CarveOptions& options) {
  return options.batch_voxels > 1 && options.method == CarveMethod::kRay &&
         options.vis_lookup == VisLookup::kFootprint && options.order == CarveOrder::kFifo &&
         options.decision == CarveDecision::kThreshold && !options.incremental_statistics;
}

// The grid of `options` over `box`, once the carving is known to fit (CHECKed).
VoxelGrid CheckedGrid(const std::vector<CalibratedView>& views,
                      const Eigen::AlignedBox3d& box,
                      const CarveOptions& options) {
  std::string reason;
  CHECK(CheckCarveFits(views, box, options, &reason)) << reason;
  return VoxelGrid(box, options.resolution);
}

// The voxels where the ground pixels' rays (CarveOptions::distant_rays of finite length) meet the
// ground's plane, inside `grid`: each saw the floor there, so that voxel is surface, as a sparse
// point's is. Kept from colour carving: the floor, seen at a slant by more photos once the space
// over it is open, is then less often carved through its top voxel (room forward, held-out sparse
// points at their depth: 80.8% without, 84.0% with). None without a ground.
std::vector<int64_t> GroundHitVoxels(const std::vector<CalibratedView>& views,
                                     const VoxelGrid& grid,
                                     const CarveOptions& options) {
  std::vector<int64_t> voxels;
  if (options.ground.empty()) return voxels;
  for (const DistantRay& ray : options.distant_rays) {
    const double descent = -options.ground.normal.dot(ray.direction);
    if (std::isinf(ray.length) || !(descent > 1e-9)) continue;
    const Eigen::Vector3d& centre = views[ray.view].centre;
    const Eigen::Vector3i voxel =
        grid.VoxelOf(centre + (options.ground.Height(centre) / descent) * ray.direction);
    if (grid.Contains(voxel)) voxels.push_back(grid.Index(voxel));
  }
  return voxels;
}

// The starting volume less the visual hull's outside (when asked and masked) and less the
// sparse points' sight lines (when asked).
Volume PreCarved(const std::vector<CalibratedView>& views,
                 Volume volume,
                 const CarveOptions& options,
                 VisualHullStatistics* hull,
                 FreeSpaceStatistics* free_space,
                 FreeSpaceStatistics* distant,
                 FreeSpaceStatistics* ground_seen,
                 std::vector<int64_t>* ground_held,
                 int64_t* beyond_ground,
                 std::vector<cv::Mat>* known_depth) {
  if (options.visual_hull) *hull = CarveVisualHull(views, &volume, options.num_threads);
  BelowGround below = SplitBelowGround(volume.grid(), options.ground);
  std::vector<int64_t> exposed;
  for (int64_t voxel : below.beyond) {
    if (!volume.IsSolid(voxel)) continue;
    volume.Carve(voxel, &exposed);
    exposed.clear();
    ++*beyond_ground;
  }
  *ground_held = std::move(below.held);
  if (options.free_space_margin_voxels > 0.0 && !options.surface_points.empty()) {
    *free_space = CarveFreeSpace(views, options.surface_points, options.free_space_margin_voxels,
                                 &volume, options.num_threads, options.ground);
  }
  if (options.protect_surface_points || !options.distant_rays.empty()) {
    *known_depth = KnownSurfaceDepths(views, volume.grid(), options.surface_points);
  }
  if (!options.distant_rays.empty()) {
    const double margin = options.free_space_margin_voxels > 0.0 ? options.free_space_margin_voxels
                                                                 : kKnownSurfaceMarginVoxels;
    // The distant pixels' rays (infinite), then the ground pixels' (ending near the ground).
    std::vector<DistantRay> rays[2];
    for (const DistantRay& ray : options.distant_rays) rays[std::isinf(ray.length) ? 0 : 1].push_back(ray);
    FreeSpaceStatistics* statistics[2] = {distant, ground_seen};
    for (int kind = 0; kind < 2; ++kind) {
      if (rays[kind].empty()) continue;
      *statistics[kind] = CarveDistantRays(views, rays[kind], options.surface_points, margin,
                                           *ground_held, &volume, options.num_threads, known_depth,
                                           options.ground);
    }
  }
  return volume;
}

}  // namespace

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
      volume_(PreCarved(views, std::move(start), options, &visual_hull_, &free_space_,
                        &distant_, &ground_seen_, &ground_held_, &beyond_ground_carved_, &known_depth_)),
      workers_(static_cast<int>(views.size()),
               options.method == CarveMethod::kRay ? options.num_threads : 1),
      visibility_(factory ? factory(views, volume_)
                          : MakeVisibility(views, volume_, options, &workers_)),
      ray_visibility_(dynamic_cast<RayCastVisibility*>(visibility_.get())),
      test_(options.consistency, options.threshold, options.min_views, options.adaptive_threshold,
            options.correct_view_count, options.spread_floor),
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
  // Made for the distant rays alone: the known surface protects only when asked.
  if (!options.protect_surface_points) std::vector<cv::Mat>().swap(known_depth_);
  if (options.protect_surface_points || !options.ground.empty() ||
      !options.interior_held.empty()) {
    protected_.assign((volume_.grid().num_voxels() + 63) / 64, 0);
  }
  if (options.protect_surface_points) {
    for (int64_t voxel : SurfacePointVoxels(volume_.grid(), options.surface_points)) {
      protected_[voxel >> 6] |= uint64_t{1} << (voxel & 63);
    }
  }
  for (int64_t voxel : options.interior_held) protected_[voxel >> 6] |= uint64_t{1} << (voxel & 63);
  for (int64_t voxel : ground_held_) protected_[voxel >> 6] |= uint64_t{1} << (voxel & 63);
  for (int64_t voxel : GroundHitVoxels(views, volume_.grid(), options)) {
    protected_[voxel >> 6] |= uint64_t{1} << (voxel & 63);
  }
  ground_voxels_ = static_cast<int64_t>(ground_held_.size());
  std::vector<int64_t>().swap(ground_held_);
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

}  // namespace raycarve
