#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "carve/volume.h"

namespace raycarve {

// Which blocks of 4x4x4 voxels of a volume hold a solid voxel: a coarse map that lets a ray
// skip empty space four voxels at a time (RayImage::Initialise). Blocks on the far edges of a
// grid whose dimensions are not multiples of 4 are partial. A snapshot: carving the volume
// afterwards does not update it (it stays conservative: a block marked empty stays empty).
// Memory: a byte per block (1/64 byte per voxel).
class BlockOccupancy {
 public:
  static constexpr int kShift = 2;           // block coordinate = voxel coordinate >> kShift
  static constexpr int kSize = 1 << kShift;  // voxels per block along each axis

  explicit BlockOccupancy(const Volume& volume);

  const Eigen::Vector3i& dimensions() const { return dimensions_; }  // blocks along each axis
  bool IsOccupied(int x, int y, int z) const {
    return occupied_[x + static_cast<int64_t>(dimensions_.x()) *
                             (y + static_cast<int64_t>(dimensions_.y()) * z)] != 0;
  }
  // By block index x + nx * (y + ny * z).
  bool IsOccupied(int64_t block) const { return occupied_[block] != 0; }
  int64_t num_occupied() const { return num_occupied_; }
  int64_t num_blocks() const { return static_cast<int64_t>(occupied_.size()); }
  // The occupied blocks a ray from outside them must cross first to reach any occupied block:
  // those with an unoccupied 6-neighbour or on the edge of the grid of blocks. Their block
  // coordinates.
  const std::vector<Eigen::Vector3i>& boundary() const { return boundary_; }

 private:
  Eigen::Vector3i dimensions_;
  std::vector<uint8_t> occupied_;
  int64_t num_occupied_ = 0;
  std::vector<Eigen::Vector3i> boundary_;
};

}  // namespace raycarve
