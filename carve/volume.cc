#include "carve/volume.h"

#include <glog/logging.h>

namespace raycarve {
namespace {

const Eigen::Vector3i kNeighbours[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0},
                                        {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

}  // namespace

Volume::Volume(const VoxelGrid& grid) : grid_(grid) {
  const int64_t words = (grid.num_voxels() + 63) / 64;
  solid_.assign(words, ~uint64_t{0});
  surface_.assign(words, 0);
  // Clear the padding bits beyond the last voxel.
  const int64_t tail = grid.num_voxels() & 63;
  if (tail != 0) solid_.back() = (uint64_t{1} << tail) - 1;
  num_solid_ = grid.num_voxels();
  const Eigen::Vector3i& n = grid.dimensions();
  for (int z = 0; z < n.z(); ++z) {
    for (int y = 0; y < n.y(); ++y) {
      const bool yz_border = z == 0 || z == n.z() - 1 || y == 0 || y == n.y() - 1;
      for (int x = 0; x < n.x(); ++x) {
        if (yz_border || x == 0 || x == n.x() - 1) {
          Set(&surface_, grid.Index(Eigen::Vector3i(x, y, z)));
          ++num_surface_;
        }
      }
    }
  }
}

Volume::Volume(const VoxelGrid& grid, std::vector<uint64_t> solid)
    : grid_(grid), solid_(std::move(solid)) {
  CHECK_EQ(static_cast<int64_t>(solid_.size()), (grid.num_voxels() + 63) / 64);
  const int64_t tail = grid.num_voxels() & 63;
  if (tail != 0) solid_.back() &= (uint64_t{1} << tail) - 1;
  surface_.assign(solid_.size(), 0);
  for (const uint64_t word : solid_) num_solid_ += __builtin_popcountll(word);
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    if (IsExposed(index)) {
      Set(&surface_, index);
      ++num_surface_;
    }
  }
}

bool Volume::IsExposed(int64_t index) const {
  if (!IsSolid(index)) return false;
  const Eigen::Vector3i voxel = grid_.Voxel(index);
  for (const Eigen::Vector3i& offset : kNeighbours) {
    const Eigen::Vector3i neighbour = voxel + offset;
    if (!grid_.Contains(neighbour) || !IsSolid(grid_.Index(neighbour))) return true;
  }
  return false;
}

void Volume::Carve(int64_t index, std::vector<int64_t>* newly_exposed) {
  CHECK(IsSolid(index)) << "carving an empty voxel " << index;
  Clear(&solid_, index);
  --num_solid_;
  if (IsSurface(index)) {
    Clear(&surface_, index);
    --num_surface_;
  }
  const Eigen::Vector3i voxel = grid_.Voxel(index);
  for (const Eigen::Vector3i& offset : kNeighbours) {
    const Eigen::Vector3i neighbour = voxel + offset;
    if (!grid_.Contains(neighbour)) continue;
    const int64_t neighbour_index = grid_.Index(neighbour);
    if (IsSolid(neighbour_index) && !IsSurface(neighbour_index)) {
      Set(&surface_, neighbour_index);
      ++num_surface_;
      if (newly_exposed != nullptr) newly_exposed->push_back(neighbour_index);
    }
  }
}

std::vector<int64_t> Volume::SurfaceVoxels() const {
  std::vector<int64_t> voxels;
  voxels.reserve(num_surface_);
  for (size_t word = 0; word < surface_.size(); ++word) {
    uint64_t bits = surface_[word];
    while (bits != 0) {
      const int bit = __builtin_ctzll(bits);
      voxels.push_back(static_cast<int64_t>(word) * 64 + bit);
      bits &= bits - 1;
    }
  }
  return voxels;
}

VolumeAgreement CompareVolumes(const Volume& first, const Volume& second) {
  CHECK(first.grid().dimensions() == second.grid().dimensions()) << "different grids";
  VolumeAgreement agreement;
  for (int64_t i = 0; i < first.grid().num_voxels(); ++i) {
    const bool a = first.IsSolid(i), b = second.IsSolid(i);
    agreement.solid_in_both += a && b;
    agreement.only_first += a && !b;
    agreement.only_second += b && !a;
  }
  return agreement;
}

}  // namespace raycarve
