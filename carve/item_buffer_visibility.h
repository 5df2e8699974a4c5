#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "calib/calibrated_view.h"
#include "carve/visibility.h"
#include "carve/volume.h"
#include "carve/voxel_coverage.h"

namespace raycarve {

// GVC's visibility (Culbertson, Malzbender, Slabaugh 1999), the seed paper's first baseline: an
// item buffer per view holds, per pixel, the nearest surface voxel, rendered by rasterising every
// surface voxel with a depth buffer (VoxelCoverage: exact cube projections). Vis(V) is the pixels
// whose item is V. Carving does not touch the buffers: within a pass they describe the volume as
// it was when the pass began, a subset of the true visibility, so they never cause a wrong carve.
// StartPass re-renders them when anything was carved; the carver then evaluates every surface
// voxel again, until a pass carves nothing.
//
// Memory: 4 bytes per pixel for the items, plus one view's depth buffer while rendering.
class ItemBufferVisibility : public Visibility {
 public:
  static constexpr uint32_t kNoItem = ~uint32_t{0};

  // `views` and `volume` must outlive this object. Renders the first buffers. The grid must have
  // fewer than 2^32 - 1 voxels (CHECKed; CheckCarveFits refuses larger).
  ItemBufferVisibility(const std::vector<CalibratedView>& views, const Volume& volume);

  std::string Name() const override { return "gvc"; }
  void ComputeVis(int64_t voxel, std::vector<PixelRef>* pixels) override;
  void UpdateAfterCarve(int64_t voxel,
                        const std::vector<PixelRef>& vis,
                        const std::vector<int64_t>& newly_exposed,
                        std::vector<int64_t>* changed) override;
  bool StartPass() override;
  size_t MemoryBytes() const override;

  // The item (voxel index or kNoItem) at a pixel of a view.
  uint32_t Item(int view, int pixel) const { return items_[view][pixel]; }
  int renders() const { return renders_; }

 private:
  void Render();

  const std::vector<CalibratedView>& views_;
  const Volume& volume_;
  std::vector<VoxelCoverage> coverage_;
  std::vector<std::vector<uint32_t>> items_;
  std::vector<float> depth_;  // one view's depth buffer, reused
  bool stale_ = false;        // something was carved since the last render
  int renders_ = 0;
};

}  // namespace raycarve
