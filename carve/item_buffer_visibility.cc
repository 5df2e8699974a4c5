#include "carve/item_buffer_visibility.h"

#include <limits>

#include <glog/logging.h>

namespace raycarve {

ItemBufferVisibility::ItemBufferVisibility(const std::vector<CalibratedView>& views,
                                           const Volume& volume)
    : views_(views), volume_(volume) {
  CHECK_LT(volume.grid().num_voxels(), int64_t{kNoItem}) << "grid too large for 32-bit items";
  size_t largest = 0;
  for (const CalibratedView& view : views) {
    coverage_.emplace_back(view, volume.grid());
    items_.emplace_back(static_cast<size_t>(view.width) * view.height, kNoItem);
    largest = std::max(largest, items_.back().size());
  }
  depth_.resize(largest);
  Render();
}

void ItemBufferVisibility::Render() {
  const std::vector<int64_t> surface = volume_.SurfaceVoxels();
  for (size_t v = 0; v < views_.size(); ++v) {
    std::vector<uint32_t>& items = items_[v];
    std::fill(items.begin(), items.end(), kNoItem);
    std::fill(depth_.begin(), depth_.begin() + items.size(), std::numeric_limits<float>::max());
    for (const int64_t voxel : surface) {
      const uint32_t item = static_cast<uint32_t>(voxel);
      coverage_[v].ForEach(volume_.grid().Voxel(voxel), [&](int pixel, double t) {
        const float depth = static_cast<float>(t);
        // Ties (a ray through a shared face or edge, in float) go to the lower index, as in
        // the layered depth images.
        if (depth < depth_[pixel] || (depth == depth_[pixel] && item < items[pixel])) {
          depth_[pixel] = depth;
          items[pixel] = item;
        }
      });
    }
  }
  stale_ = false;
  ++renders_;
}

void ItemBufferVisibility::ComputeVis(int64_t voxel, std::vector<PixelRef>* pixels) {
  const uint32_t item = static_cast<uint32_t>(voxel);
  AppendVoxelPixels(views_, volume_.grid(), voxel,
                    [&](size_t v, int pixel) { return items_[v][pixel] == item; }, pixels);
}

void ItemBufferVisibility::UpdateAfterCarve(int64_t /*voxel*/,
                                            const std::vector<PixelRef>& /*vis*/,
                                            const std::vector<int64_t>& /*newly_exposed*/,
                                            std::vector<int64_t>* /*changed*/) {
  // The buffers stay as they are until the next pass; newly exposed voxels are judged then.
  stale_ = true;
}

bool ItemBufferVisibility::StartPass() {
  if (!stale_) return false;
  Render();
  return true;
}

size_t ItemBufferVisibility::MemoryBytes() const {
  size_t bytes = depth_.capacity() * sizeof(float);
  for (const std::vector<uint32_t>& items : items_) bytes += items.capacity() * sizeof(uint32_t);
  return bytes;
}

}  // namespace raycarve
