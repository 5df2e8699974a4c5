#include "carve/carver.h"

#include <chrono>
#include <cmath>
#include <deque>
#include <sstream>

#include <glog/logging.h>

#include "carve/ray_cast_visibility.h"

namespace raycarve {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

constexpr double kBytesPerRay = 20.0;
// Solid, surface and in-queue bits, plus a generous byte for the CVSVL's entries.
constexpr double kBytesPerVoxel = 3.0 / 8.0 + 1.0;

// Groups `vis` (view by view) into per-view colour statistics.
void GatherColours(const std::vector<CalibratedView>& views,
                   const std::vector<PixelRef>& vis,
                   std::vector<ViewColourStats>* stats) {
  stats->clear();
  for (const PixelRef& ref : vis) {
    if (stats->empty() || stats->back().view != static_cast<int>(ref.view)) {
      stats->emplace_back();
      stats->back().view = static_cast<int>(ref.view);
    }
    const uint8_t* rgb = views[ref.view].image.data + 3 * static_cast<size_t>(ref.pixel);
    stats->back().Add(Eigen::Vector3d(rgb[0], rgb[1], rgb[2]));
  }
}

}  // namespace

bool CarveOptions::IsValid(std::string* reason) const {
  if (resolution < 1 || resolution > 4096) {
    *reason = "resolution must be in [1, 4096], got " + std::to_string(resolution);
    return false;
  }
  if (!(threshold >= 0.0) || !std::isfinite(threshold)) {
    *reason = "threshold must be a finite number >= 0";
    return false;
  }
  if (min_views < 1) {
    *reason = "min_views must be >= 1";
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
       << " evaluated in " << carve_seconds << " s (set-up " << setup_seconds << " s), "
       << final_surface << " surface voxels (" << visible_surface << " seen), peak memory "
       << peak_memory_bytes / (1024.0 * 1024.0) << " MiB";
  return text.str();
}

bool CheckCarveFits(const std::vector<CalibratedView>& views,
                    const Eigen::AlignedBox3d& box,
                    const CarveOptions& options,
                    std::string* reason) {
  if (!options.IsValid(reason)) return false;
  double ray_bytes = 0.0;
  for (const CalibratedView& view : views) ray_bytes += kBytesPerRay * view.width * view.height;
  const double max_bytes = options.max_memory_gib * 1024.0 * 1024.0 * 1024.0;
  if (ray_bytes > max_bytes) {
    std::ostringstream text;
    text << "the rays of " << views.size() << " views need " << ray_bytes / (1 << 30)
         << " GiB, above max_memory_gib " << options.max_memory_gib;
    *reason = text.str();
    return false;
  }
  return CheckGridFits(box, options.resolution, kBytesPerVoxel, max_bytes - ray_bytes, reason);
}

CarveResult CarveVolume(const std::vector<CalibratedView>& views,
                        const Eigen::AlignedBox3d& box,
                        const CarveOptions& options,
                        const std::function<void(const CarveProgress&)>& progress,
                        double progress_interval_seconds) {
  std::string reason;
  CHECK(CheckCarveFits(views, box, options, &reason)) << reason;
  const Clock::time_point setup_start = Clock::now();
  CarveResult result{VoxelGrid(box, options.resolution)};
  Volume& volume = result.volume;
  CarveStatistics& statistics = result.statistics;
  statistics.dimensions = volume.grid().dimensions();
  statistics.voxel_size = volume.grid().voxel_size();
  statistics.num_voxels = volume.grid().num_voxels();
  statistics.initial_surface = volume.num_surface();

  RayCastVisibility visibility(views, volume);
  statistics.visibility = visibility.Name();
  const ConsistencyTest test(options.consistency, options.threshold, options.min_views);

  // The CVSVL: first in, first out; a voxel is queued at most once at a time.
  std::deque<int64_t> queue;
  std::vector<uint64_t> queued((volume.grid().num_voxels() + 63) / 64, 0);
  auto enqueue = [&](int64_t voxel) {
    uint64_t& word = queued[voxel >> 6];
    const uint64_t bit = uint64_t{1} << (voxel & 63);
    if (word & bit) return;
    word |= bit;
    queue.push_back(voxel);
  };
  for (int64_t voxel : volume.SurfaceVoxels()) enqueue(voxel);
  statistics.setup_seconds = SecondsSince(setup_start);

  const Clock::time_point start = Clock::now();
  size_t max_queue = queue.size();
  std::vector<PixelRef> vis;
  std::vector<ViewColourStats> stats;
  std::vector<int64_t> exposed, changed;
  double next_report = progress_interval_seconds;
  double next_sample = 0.0;
  auto sample = [&](double seconds) {
    statistics.curve.push_back({seconds, statistics.carved, statistics.evaluated});
  };
  sample(0.0);
  while (!queue.empty()) {
    const int64_t voxel = queue.front();
    queue.pop_front();
    queued[voxel >> 6] &= ~(uint64_t{1} << (voxel & 63));
    if (!volume.IsSolid(voxel)) continue;
    vis.clear();
    visibility.ComputeVis(voxel, &vis);
    GatherColours(views, vis, &stats);
    ++statistics.evaluated;
    if (!test.Evaluate(stats).consistent) {
      exposed.clear();
      changed.clear();
      volume.Carve(voxel, &exposed);
      visibility.UpdateAfterCarve(voxel, vis, exposed, &changed);
      for (int64_t next : changed) enqueue(next);
      ++statistics.carved;
      max_queue = std::max(max_queue, queue.size());
    }
    if ((statistics.evaluated & 1023) == 0) {
      const double seconds = SecondsSince(start);
      if (seconds >= next_sample) {
        sample(seconds);
        next_sample = seconds + 0.05;
      }
      if (progress && seconds >= next_report) {
        progress({statistics.evaluated, statistics.carved, static_cast<int64_t>(queue.size()),
                  seconds});
        next_report = seconds + progress_interval_seconds;
      }
    }
  }
  statistics.carve_seconds = SecondsSince(start);
  sample(statistics.carve_seconds);
  statistics.peak_memory_bytes = volume.MemoryBytes() + visibility.MemoryBytes() +
                                 queued.size() * sizeof(uint64_t) + max_queue * sizeof(int64_t);

  // Colour every final surface voxel from its visible pixels.
  const Clock::time_point colour_start = Clock::now();
  for (int64_t voxel : volume.SurfaceVoxels()) {
    vis.clear();
    visibility.ComputeVis(voxel, &vis);
    GatherColours(views, vis, &stats);
    const Consistency consistency = test.Evaluate(stats);
    ColouredVoxel coloured;
    coloured.index = voxel;
    coloured.colour = consistency.colour.cast<float>();
    coloured.num_views = consistency.num_views;
    coloured.num_pixels = consistency.num_pixels;
    if (coloured.num_pixels > 0) ++statistics.visible_surface;
    result.surface.push_back(coloured);
  }
  statistics.colour_seconds = SecondsSince(colour_start);
  statistics.final_surface = volume.num_surface();
  statistics.final_solid = volume.num_solid();
  if (progress) {
    progress({statistics.evaluated, statistics.carved, 0, statistics.carve_seconds});
  }
  return result;
}

}  // namespace raycarve
