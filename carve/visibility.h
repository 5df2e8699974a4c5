#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "calib/calibrated_view.h"
#include "carve/footprint.h"
#include "carve/voxel_grid.h"

namespace raycarve {

// One pixel of one view. Made without values unless given them: a Vis buffer grows by a
// footprint's area before the scan writes it (AppendMatchingPixels), and zeroing it first
// took 3% of a carve's instructions.
struct PixelRef {
  PixelRef() {}  // NOLINT: uninitialised on purpose
  PixelRef(uint32_t view_index, uint32_t pixel_index) : view(view_index), pixel(pixel_index) {}
  uint32_t view;
  uint32_t pixel;  // row * width + col
};

// Appends to `pixels` every pixel of `footprint` (in an image `width` wide, row by row) for which
// matches(pixel) holds, as pixels of `view`: how each method reads its per-pixel structure (ray
// keys, item buffer, list heads) for Vis(V).
template <typename Matches>
void AppendMatchingPixels(const Footprint& footprint, int width, uint32_t view, Matches&& matches,
                          std::vector<PixelRef>* pixels) {
  if (footprint.empty()) return;
  // Every pixel is written and the end moves on only past those that match: no branch on the
  // match, which is as likely as not along a voxel's edge.
  const size_t first = pixels->size();
  pixels->resize(first + static_cast<size_t>(footprint.area()));
  PixelRef* out = pixels->data() + first;
  for (int row = footprint.row_min; row <= footprint.row_max; ++row) {
    const int base = row * width;
    for (int col = footprint.col_min; col <= footprint.col_max; ++col) {
      *out = {view, static_cast<uint32_t>(base + col)};
      out += matches(base + col) ? 1 : 0;
    }
  }
  pixels->resize(static_cast<size_t>(out - pixels->data()));
}

// Appends to `pixels`, view by view, every pixel of `voxel`'s footprint in each of `views` for
// which matches(view index, pixel) holds: Vis(V) of the methods that keep a structure per view.
template <typename Matches>
void AppendVoxelPixels(const std::vector<CalibratedView>& views, const VoxelGrid& grid,
                       int64_t voxel, Matches&& matches, std::vector<PixelRef>* pixels) {
  const Eigen::Vector3i coordinates = grid.Voxel(voxel);
  for (size_t v = 0; v < views.size(); ++v) {
    const CalibratedView& view = views[v];
    const Footprint footprint = ComputeFootprint(view.P, view.width, view.height, grid, coordinates);
    AppendMatchingPixels(footprint, view.width, static_cast<uint32_t>(v),
                         [&](int pixel) { return matches(v, pixel); }, pixels);
  }
}

// How the carver learns which pixels see which voxel: the one thing in which ray casting, GVC
// and GVC-LDI differ. Everything else (grid, surface, footprints, consistency, colouring) is
// shared by the carver.
class Visibility {
 public:
  virtual ~Visibility() = default;

  virtual std::string Name() const = 0;

  // Vis(V): appends to `pixels` every pixel, in every view, at which `voxel` is the nearest solid
  // voxel as this method currently knows it, view by view.
  virtual void ComputeVis(int64_t voxel, std::vector<PixelRef>* pixels) = 0;

  // Called after `voxel` was carved (the volume is already updated). Inputs: `vis`, the voxel's
  // last Vis(V); `newly_exposed`, the interior voxels the carving made surface. Outputs: updates
  // the method's structures and appends to `changed` every voxel whose visibility may have
  // changed (they must be re-evaluated; duplicates are allowed).
  virtual void UpdateAfterCarve(int64_t voxel,
                                const std::vector<PixelRef>& vis,
                                const std::vector<int64_t>& newly_exposed,
                                std::vector<int64_t>* changed) = 0;

  // |Vis(V)|, for ordering the CVSVL by evidence. The default computes Vis(V); a method may
  // keep counts instead.
  virtual int64_t CountVis(int64_t voxel) {
    scratch_.clear();
    ComputeVis(voxel, &scratch_);
    return static_cast<int64_t>(scratch_.size());
  }

  // Called when the CVSVL has run empty. An incremental method (ray casting, GVC-LDI) has
  // nothing left to learn and returns false: the carving has converged. A pass-based method
  // (GVC) refreshes its structures and returns true when anything was carved since its last
  // refresh; the carver then queues every surface voxel again for another pass.
  virtual bool StartPass() { return false; }

  // Bytes held by the method's structures.
  virtual size_t MemoryBytes() const = 0;

 private:
  std::vector<PixelRef> scratch_;
};

}  // namespace raycarve
