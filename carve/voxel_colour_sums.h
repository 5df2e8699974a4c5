#pragma once

#include <cstdint>
#include <vector>

#include "carve/consistency.h"

namespace raycarve {

// Colour statistics per voxel and view, kept incrementally (the seed paper's section 4): when a
// ray arrives at a voxel its pixel's colour is added, and a carved voxel's sums are dropped (its
// rays have all moved on). Evaluating a voxel then reads its sums instead of gathering the
// pixels of Vis(V) again.
//
// Sums are integers, so Stats gives exactly what gathering the same pixels gives (colours are
// whole numbers, and so are their double sums below 2^53).
//
// Memory: 4 bytes per voxel for a slot index, and per voxel that holds rays a slot of
// 56 bytes per view; slots of carved voxels are reused.
class VoxelColourSums {
 public:
  VoxelColourSums(int64_t num_voxels, int num_views);

  // Adds one pixel's colour (8-bit RGB) seen in `view` to `voxel`.
  void Add(int64_t voxel, int view, const uint8_t* rgb) {
    int32_t& slot = slot_of_[voxel];
    if (slot < 0) slot = NewSlot();
    Sums& sums = slots_[static_cast<size_t>(slot) * num_views_ + view];
    ++sums.count;
    for (int c = 0; c < 3; ++c) {
      sums.sum[c] += rgb[c];
      sums.sum_squares[c] += static_cast<uint64_t>(rgb[c]) * rgb[c];
    }
  }
  // Drops `voxel`'s sums (after it was carved).
  void Release(int64_t voxel);
  // Replaces `stats` with `voxel`'s statistics, one entry per view that sees it, by view.
  void Stats(int64_t voxel, std::vector<ViewColourStats>* stats) const;

  int64_t slots_in_use() const { return static_cast<int64_t>(slots_.size() / num_views_ - free_.size()); }
  size_t MemoryBytes() const {
    return slot_of_.capacity() * sizeof(int32_t) + slots_.capacity() * sizeof(Sums) +
           free_.capacity() * sizeof(int32_t);
  }

 private:
  struct Sums {
    uint32_t count = 0;
    uint64_t sum[3] = {0, 0, 0};
    uint64_t sum_squares[3] = {0, 0, 0};
  };
  int32_t NewSlot();

  int num_views_;
  std::vector<int32_t> slot_of_;  // per voxel: its slot, or -1
  std::vector<Sums> slots_;       // num_views_ entries per slot
  std::vector<int32_t> free_;     // released slots
};

}  // namespace raycarve
