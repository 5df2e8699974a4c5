#include "carve/ray_cast_visibility.h"

#include <algorithm>
#include <cstdint>

#include <glog/logging.h>

#include "carve/footprint.h"

namespace raycarve {

std::string VisLookupToString(VisLookup lookup) {
  return lookup == VisLookup::kFootprint ? "footprint" : "ray_lists";
}

bool VisLookupFromString(const std::string& text, VisLookup* lookup) {
  for (VisLookup candidate : {VisLookup::kFootprint, VisLookup::kRayLists}) {
    if (text == VisLookupToString(candidate)) {
      *lookup = candidate;
      return true;
    }
  }
  return false;
}

RayCastVisibility::RayCastVisibility(const std::vector<CalibratedView>& views,
                                     const Volume& volume,
                                     VisLookup lookup,
                                     bool count_rays,
                                     ViewWorkers* workers)
    : views_(views), volume_(volume), lookup_(lookup), rays_(views.size()) {
  int64_t total = 0;
  for (const CalibratedView& view : views) {
    view_offset_.push_back(static_cast<int32_t>(total));
    total += static_cast<int64_t>(view.width) * view.height;
  }
  // Where carving (a visual hull, a coarser level of detail) has emptied space, rays cross it a
  // block at a time.
  std::unique_ptr<BlockOccupancy> blocks;
  if (volume.num_solid() < volume.grid().num_voxels()) {
    blocks = std::make_unique<BlockOccupancy>(volume);
  }
  auto make_rays = [&](int view) {
    const CalibratedView& v = views[view];
    const Eigen::Matrix3d world_from_pixel = v.WorldFromPixel();
    // Rays only where the view holds photo data on the object: background pixels never enter
    // Vis(V) or consistency.
    const cv::Mat usable = v.mask.empty() ? v.valid : (v.valid & v.mask);
    rays_[view] = std::make_unique<RayImage>(volume.grid(), world_from_pixel, v.centre, v.width,
                                             v.height, usable);
    rays_[view]->Initialise(volume, blocks.get());
  };
  if (workers != nullptr && workers->num_groups() > 1 &&
      workers->num_views() == static_cast<int>(views.size())) {
    auto task = [&](int group) {
      for (int view : workers->ViewsOf(group)) make_rays(view);
    };
    workers->Run(task);
  } else {
    for (int view = 0; view < static_cast<int>(views.size()); ++view) make_rays(view);
  }
  if (count_rays) {
    counts_.assign(volume.grid().num_voxels(), 0);
    for (const std::unique_ptr<RayImage>& rays : rays_) {
      for (int pixel = 0; pixel < rays->num_pixels(); ++pixel) {
        const int64_t current = rays->CurrentVoxel(pixel);
        if (current != RayImage::kNoVoxel && counts_[current] != UINT16_MAX) ++counts_[current];
      }
    }
  }
  if (lookup_ != VisLookup::kRayLists) return;
  CHECK_LT(total, int64_t{1} << 31) << "too many rays for 32-bit ray lists";
  head_.assign(volume.grid().num_voxels(), -1);
  next_.assign(total, -1);
  // Linked in reverse so that each list starts in row-major order (ComputeVis sorts anyway).
  for (int v = static_cast<int>(views.size()) - 1; v >= 0; --v) {
    for (int pixel = rays_[v]->num_pixels() - 1; pixel >= 0; --pixel) {
      const int64_t current = rays_[v]->CurrentVoxel(pixel);
      if (current != RayImage::kNoVoxel) Link(view_offset_[v] + pixel, current);
    }
  }
}

void RayCastVisibility::ComputeVis(int64_t voxel, std::vector<PixelRef>* pixels) {
  if (lookup_ == VisLookup::kRayLists) {
    const size_t first = pixels->size();
    for (int32_t ray = head_[voxel]; ray != -1; ray = next_[ray]) {
      const uint32_t view = static_cast<uint32_t>(
          std::upper_bound(view_offset_.begin(), view_offset_.end(), ray) - view_offset_.begin() - 1);
      pixels->push_back({view, static_cast<uint32_t>(ray - view_offset_[view])});
    }
    std::sort(pixels->begin() + first, pixels->end(), [](const PixelRef& a, const PixelRef& b) {
      return a.view != b.view ? a.view < b.view : a.pixel < b.pixel;
    });
    return;
  }
  const Eigen::Vector3i coordinates = volume_.grid().Voxel(voxel);
  for (int view = 0; view < static_cast<int>(views_.size()); ++view) {
    ComputeVisInView(coordinates, view, pixels);
  }
}

void RayCastVisibility::ComputeVisInView(const Eigen::Vector3i& voxel,
                                         int view,
                                         std::vector<PixelRef>* pixels) const {
  AppendVis(VisFootprint(voxel, view), voxel, view, pixels);
}

Footprint RayCastVisibility::VisFootprint(const Eigen::Vector3i& voxel, int view) const {
  // No ray of this view ends in the voxel: nothing to scan.
  if (!rays_[view]->MayEndIn(volume_.grid().Index(voxel))) return Footprint();
  const CalibratedView& v = views_[view];
  return ComputeFootprint(v.P, v.width, v.height, volume_.grid(), voxel);
}

void RayCastVisibility::AppendVis(const Footprint& footprint,
                                  const Eigen::Vector3i& voxel,
                                  int view,
                                  std::vector<PixelRef>* pixels) const {
  const uint32_t key = rays_[view]->Key(voxel);
  const uint32_t* keys = rays_[view]->keys();
  AppendMatchingPixels(footprint, views_[view].width, static_cast<uint32_t>(view),
                       [&](int pixel) { return keys[pixel] == key; }, pixels);
}

void RayCastVisibility::PrefetchRays(const Footprint& footprint, int view) const {
  const uint32_t* keys = rays_[view]->keys();
  const int width = views_[view].width;
  // A row of a footprint spans a cache line or two: its first and last key fetch both.
  for (int row = footprint.row_min; row <= footprint.row_max; ++row) {
    __builtin_prefetch(keys + static_cast<size_t>(row) * width + footprint.col_min);
    __builtin_prefetch(keys + static_cast<size_t>(row) * width + footprint.col_max);
  }
}

void RayCastVisibility::AdvanceRays(const PixelRef* begin,
                                    const PixelRef* end,
                                    std::vector<int64_t>* reached) {
  CHECK(ViewParallel());
  for (const PixelRef* ref = begin; ref != end; ++ref) {
    const int64_t next = rays_[ref->view]->Advance(static_cast<int>(ref->pixel), volume_);
    if (next != RayImage::kNoVoxel) reached->push_back(next);
  }
}

void RayCastVisibility::AdvanceRaysFrom(const Eigen::Vector3i& voxel,
                                        const PixelRef* begin,
                                        const PixelRef* end,
                                        std::vector<int64_t>* reached) {
  CHECK(ViewParallel());
  if (begin == end) return;
  rays_[begin->view]->AdvanceFromCarved(voxel, begin, end, volume_, reached);
}

void RayCastVisibility::UpdateAfterCarve(int64_t voxel,
                                         const std::vector<PixelRef>& vis,
                                         const std::vector<int64_t>& /*newly_exposed*/,
                                         std::vector<int64_t>* changed) {
  // Vis(V) is every ray that ended in V, so V's list is consumed whole.
  if (lookup_ == VisLookup::kRayLists) head_[voxel] = -1;
  if (!counts_.empty()) counts_[voxel] = 0;
  for (const PixelRef& ref : vis) {
    const int64_t next = rays_[ref.view]->Advance(static_cast<int>(ref.pixel), volume_);
    if (next == RayImage::kNoVoxel) continue;
    changed->push_back(next);
    if (!counts_.empty() && counts_[next] != UINT16_MAX) ++counts_[next];
    if (lookup_ == VisLookup::kRayLists) Link(view_offset_[ref.view] + ref.pixel, next);
  }
}

int64_t RayCastVisibility::CountVis(int64_t voxel) {
  if (!counts_.empty()) return counts_[voxel];
  return Visibility::CountVis(voxel);
}

size_t RayCastVisibility::MemoryBytes() const {
  size_t bytes = (head_.capacity() + next_.capacity()) * sizeof(int32_t) +
                 counts_.capacity() * sizeof(uint16_t);
  for (const std::unique_ptr<RayImage>& rays : rays_) bytes += rays->MemoryBytes();
  return bytes;
}

}  // namespace raycarve
