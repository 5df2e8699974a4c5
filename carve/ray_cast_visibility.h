#pragma once

#include <vector>

#include "calib/calibrated_view.h"
#include "carve/ray_image.h"
#include "carve/visibility.h"
#include "carve/volume.h"

namespace raycarve {

// The seed paper's visibility: an image of rays per view as the item buffer.
// Vis(V) scans V's footprint in each view for pixels whose ray currently ends in V. Carving V
// steps only the rays of Vis(V) to their next solid voxel, which is reported as changed.
// Masked-out pixels (view.valid == 0) get no ray.
class RayCastVisibility : public Visibility {
 public:
  // `volume` must outlive this object; rays start at its first solid voxels.
  RayCastVisibility(const std::vector<CalibratedView>& views, const Volume& volume);

  std::string Name() const override { return "ray"; }
  void ComputeVis(int64_t voxel, std::vector<PixelRef>* pixels) override;
  void UpdateAfterCarve(int64_t voxel,
                        const std::vector<PixelRef>& vis,
                        const std::vector<int64_t>& newly_exposed,
                        std::vector<int64_t>* changed) override;
  size_t MemoryBytes() const override;

  const RayImage& rays(int view) const { return rays_[view]; }

 private:
  const std::vector<CalibratedView>& views_;
  const Volume& volume_;
  std::vector<RayImage> rays_;
};

}  // namespace raycarve
