#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "calib/ray_box.h"  // ClipRayToBox, for the grid's users

namespace raycarve {

// A regular grid of cubic voxels over a world-space box.
//
// The longest axis of the box gets `resolution` voxels; the others get as many whole voxels of
// the same size as cover their extent (so the grid may reach slightly beyond the box on those
// axes, never less). Voxel (i, j, k) spans origin + size * [i, i+1) x [j, j+1) x [k, k+1).
// Linear index: i + nx * (j + ny * k).
class VoxelGrid {
 public:
  VoxelGrid(const Eigen::AlignedBox3d& box, int resolution);

  const Eigen::Vector3i& dimensions() const { return dimensions_; }
  double voxel_size() const { return voxel_size_; }
  const Eigen::Vector3d& origin() const { return origin_; }
  int64_t num_voxels() const {
    return static_cast<int64_t>(dimensions_.x()) * dimensions_.y() * dimensions_.z();
  }
  // The box the voxels cover (contains the requested box).
  Eigen::AlignedBox3d Box() const;
  // The grid of this grid's voxels [lo, hi) (per axis; non-empty and inside, CHECKed): the same
  // voxel size, its voxel v being this grid's voxel lo + v. A tile of a carve (carve/tiling.h).
  VoxelGrid Region(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) const;

  bool Contains(const Eigen::Vector3i& voxel) const {
    return (voxel.array() >= 0).all() && (voxel.array() < dimensions_.array()).all();
  }
  int64_t Index(const Eigen::Vector3i& voxel) const {
    return voxel.x() + static_cast<int64_t>(dimensions_.x()) *
                           (voxel.y() + static_cast<int64_t>(dimensions_.y()) * voxel.z());
  }
  Eigen::Vector3i Voxel(int64_t index) const;

  // The voxel holding a world point (floor of grid coordinates; may lie outside the grid).
  Eigen::Vector3i VoxelOf(const Eigen::Vector3d& world) const;
  Eigen::Vector3d Centre(const Eigen::Vector3i& voxel) const;
  // Corner c (bit 0: +x, bit 1: +y, bit 2: +z) of a voxel, in world coordinates. (Inline: every
  // footprint starts from one.)
  Eigen::Vector3d Corner(const Eigen::Vector3i& voxel, int c) const {
    const Eigen::Vector3d offset(c & 1, (c >> 1) & 1, (c >> 2) & 1);
    return origin_ + voxel_size_ * (voxel.cast<double>() + offset);
  }

 private:
  Eigen::Vector3d origin_;
  double voxel_size_;
  Eigen::Vector3i dimensions_;
};

// Checks a requested grid before any allocation: false, with a reason giving the numbers, when
// the resolution is below 1 or above 4096, or when `bytes_per_voxel` x the voxel count exceeds
// `max_bytes` (the reason states the memory the grid would need).
bool CheckGridFits(const Eigen::AlignedBox3d& box,
                   int resolution,
                   double bytes_per_voxel,
                   double max_bytes,
                   std::string* reason);

}  // namespace raycarve
