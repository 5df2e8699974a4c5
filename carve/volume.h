#pragma once

#include <cstdint>
#include <vector>

#include "carve/voxel_grid.h"

namespace raycarve {

// The carved volume as two 3D bit images over a VoxelGrid: solid voxels, and the surface (solid
// voxels with an empty 6-neighbour or on the grid's border). Everything starts solid, so the
// surface starts as the grid's border. Memory: 2 bits per voxel.
class Volume {
 public:
  explicit Volume(const VoxelGrid& grid);
  // A volume whose solid voxels are `solid` (a bit per voxel in index order, as many words as
  // the grid needs: CHECKed); the surface is computed from it.
  Volume(const VoxelGrid& grid, std::vector<uint64_t> solid);

  const VoxelGrid& grid() const { return grid_; }

  bool IsSolid(int64_t index) const { return Test(solid_, index); }
  bool IsSurface(int64_t index) const { return Test(surface_, index); }
  bool IsSolid(const Eigen::Vector3i& voxel) const {
    return grid_.Contains(voxel) && IsSolid(grid_.Index(voxel));
  }

  // Carves a solid voxel (CHECKed): it leaves the solid set and the surface, and its solid
  // 6-neighbours that were interior become surface; they are appended to `newly_exposed`.
  void Carve(int64_t index, std::vector<int64_t>* newly_exposed);

  int64_t num_solid() const { return num_solid_; }
  int64_t num_surface() const { return num_surface_; }

  // All surface voxels, in index order.
  std::vector<int64_t> SurfaceVoxels() const;

  // Whether a solid voxel has an empty 6-neighbour or lies on the border (the definition,
  // computed from the solid set; used to check the incremental surface).
  bool IsExposed(int64_t index) const;

  // The solid bits, a bit per voxel in index order.
  const std::vector<uint64_t>& solid_bits() const { return solid_; }
  // The surface bits, likewise.
  const std::vector<uint64_t>& surface_bits() const { return surface_; }

  size_t MemoryBytes() const { return (solid_.size() + surface_.size()) * sizeof(uint64_t); }

 private:
  static bool Test(const std::vector<uint64_t>& bits, int64_t index) {
    return (bits[index >> 6] >> (index & 63)) & 1u;
  }
  static void Set(std::vector<uint64_t>* bits, int64_t index) {
    (*bits)[index >> 6] |= uint64_t{1} << (index & 63);
  }
  static void Clear(std::vector<uint64_t>* bits, int64_t index) {
    (*bits)[index >> 6] &= ~(uint64_t{1} << (index & 63));
  }

  VoxelGrid grid_;
  std::vector<uint64_t> solid_;
  std::vector<uint64_t> surface_;
  int64_t num_solid_ = 0;
  int64_t num_surface_ = 0;
};

// How two carvings of the same grid agree: voxel IoU of their solid sets and the voxels on
// which they differ.
struct VolumeAgreement {
  int64_t solid_in_both = 0;
  int64_t only_first = 0;   // solid in the first volume only
  int64_t only_second = 0;  // solid in the second volume only
  int64_t differing() const { return only_first + only_second; }
  double iou() const {
    const int64_t either = solid_in_both + differing();
    return either == 0 ? 1.0 : static_cast<double>(solid_in_both) / either;
  }
};
// The grids must have the same dimensions (CHECKed).
VolumeAgreement CompareVolumes(const Volume& first, const Volume& second);

}  // namespace raycarve
