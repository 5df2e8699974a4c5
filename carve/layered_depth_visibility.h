#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "calib/calibrated_view.h"
#include "carve/visibility.h"
#include "carve/volume.h"
#include "carve/voxel_coverage.h"

namespace raycarve {

// GVC-LDI's visibility (Culbertson et al.; the seed paper's second baseline): per view and pixel,
// a layered depth image, the list of every surface voxel whose cube the pixel's ray passes
// through, sorted by depth (ties by voxel index). The head of a list is the voxel the pixel sees,
// so Vis(V) is the pixels whose head is V.
//
// Carving V (the paper's Figure 5): each newly exposed neighbour N is inserted into the list of
// every pixel it covers, then V is removed from the list of every pixel it covers; the voxels that
// become a head by either change gained pixels and are reported as changed. (Inserting first
// means a pixel that V uncovers reports only the voxel it now sees, as ray casting does.)
//
// Memory: 4 bytes per pixel for the list heads and 12 bytes per list entry; entries freed by
// carving are reused.
class LayeredDepthVisibility : public Visibility {
 public:
  // `views` and `volume` must outlive this object. Builds the lists from the volume's surface.
  // The grid must have fewer than 2^32 voxels (CHECKed; CheckCarveFits refuses larger).
  LayeredDepthVisibility(const std::vector<CalibratedView>& views, const Volume& volume);

  std::string Name() const override { return "gvc_ldi"; }
  void ComputeVis(int64_t voxel, std::vector<PixelRef>* pixels) override;
  void UpdateAfterCarve(int64_t voxel,
                        const std::vector<PixelRef>& vis,
                        const std::vector<int64_t>& newly_exposed,
                        std::vector<int64_t>* changed) override;
  size_t MemoryBytes() const override;

  // One pixel's list, nearest first: voxel indices and their depths (for tests).
  std::vector<int64_t> List(int view, int pixel) const;
  std::vector<float> Depths(int view, int pixel) const;
  size_t num_entries() const { return nodes_.size() - num_free_; }

 private:
  struct Node {
    uint32_t voxel;
    float depth;
    int32_t next;  // -1 at the end of a list
  };
  static bool Before(float depth, uint32_t voxel, const Node& node) {
    return depth < node.depth || (depth == node.depth && voxel < node.voxel);
  }
  // Inserts in depth order; true when the voxel became the head.
  bool Insert(int view, int pixel, uint32_t voxel, float depth);
  // Removes the voxel from the list (CHECKed present); true when it was the head.
  bool Remove(int view, int pixel, uint32_t voxel);
  void InsertVoxel(int64_t voxel, std::vector<int64_t>* changed);

  const std::vector<CalibratedView>& views_;
  const Volume& volume_;
  std::vector<VoxelCoverage> coverage_;
  std::vector<std::vector<int32_t>> heads_;  // per view and pixel: first node, or -1
  std::vector<Node> nodes_;
  int32_t free_ = -1;  // free nodes, linked through next
  size_t num_free_ = 0;
};

}  // namespace raycarve
