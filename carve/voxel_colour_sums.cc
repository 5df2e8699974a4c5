#include "carve/voxel_colour_sums.h"

#include <algorithm>

#include <glog/logging.h>

namespace raycarve {

VoxelColourSums::VoxelColourSums(int64_t num_voxels, int num_views)
    : num_views_(std::max(1, num_views)), slot_of_(num_voxels, -1) {}

int32_t VoxelColourSums::NewSlot() {
  if (!free_.empty()) {
    const int32_t slot = free_.back();
    free_.pop_back();
    return slot;
  }
  const size_t slots = slots_.size() / num_views_;
  CHECK_LT(slots, static_cast<size_t>(INT32_MAX)) << "too many voxels with colour sums";
  slots_.resize(slots_.size() + num_views_);
  return static_cast<int32_t>(slots);
}

void VoxelColourSums::Release(int64_t voxel) {
  int32_t& slot = slot_of_[voxel];
  if (slot < 0) return;
  std::fill_n(slots_.begin() + static_cast<size_t>(slot) * num_views_, num_views_, Sums());
  free_.push_back(slot);
  slot = -1;
}

void VoxelColourSums::Stats(int64_t voxel, std::vector<ViewColourStats>* stats) const {
  stats->clear();
  const int32_t slot = slot_of_[voxel];
  if (slot < 0) return;
  const Sums* sums = slots_.data() + static_cast<size_t>(slot) * num_views_;
  for (int view = 0; view < num_views_; ++view) {
    if (sums[view].count == 0) continue;
    ViewColourStats entry;
    entry.view = view;
    entry.count = static_cast<int>(sums[view].count);
    for (int c = 0; c < 3; ++c) {
      entry.sum[c] = static_cast<double>(sums[view].sum[c]);
      entry.sum_squares[c] = static_cast<double>(sums[view].sum_squares[c]);
    }
    stats->push_back(entry);
  }
}

}  // namespace raycarve
