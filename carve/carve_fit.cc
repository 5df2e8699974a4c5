// CheckCarveFits (the memory estimate) and MeasureBoxCoverage.
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

}  // namespace

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
      if (!view.FramesPoint(point)) continue;
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
  // Supersampling: the final level's rays and its enlarged copy of the photos (RGB, valid, mask).
  const int supersample = FinalSupersample(views, box, options);
  if (supersample > 1) bytes_per_pixel += 5.0;
  double ray_bytes = 0.0;
  for (const CalibratedView& view : views) {
    ray_bytes += bytes_per_pixel * view.width * view.height * supersample * supersample;
  }
  const double max_bytes = options.max_memory_gib * 1024.0 * 1024.0 * 1024.0;
  if (ray_bytes > max_bytes) {
    std::ostringstream text;
    text << "the " << (options.method == CarveMethod::kRay ? "rays" : "buffers") << " of "
         << views.size() << " views need " << ray_bytes / (1 << 30)
         << " GiB, above max_memory_gib " << options.max_memory_gib;
    if (supersample > 1) {
      text << " (the photos enlarged " << supersample << " times for voxels finer than a pixel: "
           << "supersample 1 carves them as they are)";
    }
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

}  // namespace raycarve
