#pragma once

#include <memory>
#include <string>
#include <vector>

#include "calib/calibrated_view.h"
#include "carve/footprint.h"
#include "carve/ray_image.h"
#include "carve/view_workers.h"
#include "carve/visibility.h"
#include "carve/volume.h"

namespace raycarve {

// How Vis(V) finds the rays that currently end in V.
enum class VisLookup {
  kFootprint,  // the seed paper: scan V's footprint in every view (cost: the footprints' area)
  kRayLists,   // the paper's "more direct" storage: each voxel keeps the list of rays ending in
               // it (cost: |Vis(V)| and a sort; 4 more bytes a ray and 4 a voxel)
};
std::string VisLookupToString(VisLookup lookup);
bool VisLookupFromString(const std::string& text, VisLookup* lookup);

// The seed paper's visibility: an image of rays per view as the item buffer.
// Vis(V) is the pixels whose ray currently ends in V, found by `lookup`; both lookups give the
// same pixels in the same order (view by view, row-major). Carving V steps only the rays of
// Vis(V) to their next solid voxel, which is reported as changed. Pixels without photo data
// (view.valid == 0) or on background (view.mask == 0 when there is a mask) get no ray.
//
// Each view's rays are independent of the others', so with the footprint lookup and no ray
// counts (ViewParallel) the carver may find Vis(V) and step rays one view at a time on several
// threads: ComputeVisInView and AdvanceRays for different views may run at once (the volume
// unchanged meanwhile), and concatenated in view order they give exactly ComputeVis and what
// UpdateAfterCarve reports.
class RayCastVisibility : public Visibility {
 public:
  // `volume` must outlive this object; rays start at its first solid voxels. With `count_rays`,
  // a count per voxel of the rays ending in it is kept (2 bytes a voxel, saturating at 65535)
  // so that CountVis costs nothing. With `workers`, the views' rays are set up in parallel.
  RayCastVisibility(const std::vector<CalibratedView>& views,
                    const Volume& volume,
                    VisLookup lookup = VisLookup::kFootprint,
                    bool count_rays = false,
                    ViewWorkers* workers = nullptr);

  std::string Name() const override { return "ray"; }
  void ComputeVis(int64_t voxel, std::vector<PixelRef>* pixels) override;
  void UpdateAfterCarve(int64_t voxel,
                        const std::vector<PixelRef>& vis,
                        const std::vector<int64_t>& newly_exposed,
                        std::vector<int64_t>* changed) override;
  int64_t CountVis(int64_t voxel) override;
  size_t MemoryBytes() const override;

  const RayImage& rays(int view) const { return *rays_[view]; }

  bool ViewParallel() const { return lookup_ == VisLookup::kFootprint && counts_.empty(); }
  // ComputeVis restricted to one view, for the voxel at grid coordinates `voxel`.
  // It is AppendVis(VisFootprint(voxel, view), voxel, view, pixels), in two steps so that a
  // caller can fetch the memory a later scan reads (PrefetchRays) while scanning.
  void ComputeVisInView(const Eigen::Vector3i& voxel, int view, std::vector<PixelRef>* pixels) const;
  // The pixels of `view` to scan for the voxel: its footprint, or none when no ray of the view
  // ends in it.
  Footprint VisFootprint(const Eigen::Vector3i& voxel, int view) const;
  // Appends the pixels of `footprint` whose ray ends in `voxel`.
  void AppendVis(const Footprint& footprint,
                 const Eigen::Vector3i& voxel,
                 int view,
                 std::vector<PixelRef>* pixels) const;
  // A hint: starts fetching the rays of `footprint` into the cache. Changes nothing.
  void PrefetchRays(const Footprint& footprint, int view) const;
  // Steps the rays of pixels [begin, end) (their voxel was carved) and appends the solid voxel
  // each reaches, as UpdateAfterCarve reports them (footprint lookup, no counts: CHECKed).
  void AdvanceRays(const PixelRef* begin, const PixelRef* end, std::vector<int64_t>* reached);
  // AdvanceRays for pixels [begin, end) of one view, all of which ended in `voxel` (the same).
  void AdvanceRaysFrom(const Eigen::Vector3i& voxel,
                       const PixelRef* begin,
                       const PixelRef* end,
                       std::vector<int64_t>* reached);

 private:
  // Ray lists: a ray's global id is view_offset_[view] + pixel.
  void Link(int32_t ray, int64_t voxel) {
    next_[ray] = head_[voxel];
    head_[voxel] = ray;
  }

  const std::vector<CalibratedView>& views_;
  const Volume& volume_;
  VisLookup lookup_;
  std::vector<std::unique_ptr<RayImage>> rays_;  // per view
  std::vector<int32_t> view_offset_;
  std::vector<int32_t> head_;  // per voxel: a ray ending in it, or -1
  std::vector<int32_t> next_;  // per ray: the next ray ending in the same voxel, or -1
  std::vector<uint16_t> counts_;  // per voxel, with count_rays: rays ending in it
};

}  // namespace raycarve
