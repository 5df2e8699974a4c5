#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "carve/volume.h"
#include "carve/voxel_grid.h"

namespace raycarve {

// The image of rays of one view: the seed paper's item buffer. One ray per pixel, from the camera
// centre through the pixel centre, clipped to the grid's box, with the state of an Amanatides-Woo
// traversal (the current voxel and, per axis, the ray parameter of the next voxel boundary).
//
// Inputs: the view's 3x4 projection in its pinhole form (K, cam_from_world rotation, centre),
// its size, and an optional mask of pixels that hold photo data (rays are only made there).
// Outputs: per pixel, the current voxel (the nearest solid voxel along the ray, once Initialise
// and Advance keep it so) or kNoVoxel when the ray missed the box, has left it, or the pixel is
// masked out.
//
// Memory: 20 bytes per pixel (the direction is recomputed from the pixel when a ray is stepped).
// Coordinates are kept as 16-bit fields of a 64-bit key per pixel, tMax in a separate array.
// Voxel coordinates are stored in 16 bits: grids up to 32767 voxels along an axis.
class RayImage {
 public:
  static constexpr int64_t kNoVoxel = -1;

  // `world_from_pixel` maps homogeneous COLMAP pixel coordinates (x, y, 1) to a world-space
  // direction (R^T K^-1); `centre` is the camera centre in world coordinates.
  RayImage(const VoxelGrid& grid,
           const Eigen::Matrix3d& world_from_pixel,
           const Eigen::Vector3d& centre,
           int width,
           int height,
           const cv::Mat& valid = cv::Mat());

  int width() const { return width_; }
  int height() const { return height_; }
  int num_pixels() const { return width_ * height_; }

  // Moves every ray to the first solid voxel of `volume` along it.
  void Initialise(const Volume& volume);

  int64_t CurrentVoxel(int pixel) const {
    const uint64_t key = keys_[pixel];
    return key == kInactive ? kNoVoxel : grid_.Index(Unpack(key));
  }

  // A voxel's key: what keys() holds for a ray whose current voxel it is. Comparing keys is how
  // a footprint is scanned without decoding every ray.
  static uint64_t Key(const Eigen::Vector3i& voxel) {
    return static_cast<uint64_t>(static_cast<uint16_t>(voxel.x())) |
           static_cast<uint64_t>(static_cast<uint16_t>(voxel.y())) << 16 |
           static_cast<uint64_t>(static_cast<uint16_t>(voxel.z())) << 32;
  }
  // Per pixel, row-major: the current voxel's key, or a value no voxel has when the ray is gone.
  const uint64_t* keys() const { return keys_.data(); }

  // Steps the ray at `pixel` until its current voxel is solid in `volume` or it leaves the box
  // (then kNoVoxel). Returns the new current voxel. A ray already at a solid voxel stays.
  // Cost: one step per voxel passed (Amanatides-Woo).
  int64_t Advance(int pixel, const Volume& volume);

  // The voxel the ray at `pixel` would reach if its current voxel were carved: the first solid
  // voxel of `volume` beyond it, or kNoVoxel. Changes nothing.
  int64_t PeekBeyondCurrent(int pixel, const Volume& volume) const;

  // The ray parameter convention: world point = centre + t * Direction(pixel).
  Eigen::Vector3d Direction(int pixel) const;

  size_t MemoryBytes() const {
    return keys_.capacity() * sizeof(uint64_t) + t_max_.capacity() * sizeof(TMax);
  }

 private:
  static constexpr uint64_t kInactive = ~uint64_t{0};
  // Ray parameter of the next voxel boundary crossing, per axis.
  struct TMax {
    float axis[3];
  };
  static Eigen::Vector3i Unpack(uint64_t key) {
    return Eigen::Vector3i(static_cast<int>(key & 0xffff), static_cast<int>((key >> 16) & 0xffff),
                           static_cast<int>((key >> 32) & 0xffff));
  }

  void InitialiseRay(int pixel);
  // Steps from voxel/t_max (updated in place) until a solid voxel (returned, its index) or the
  // box's edge (kNoVoxel). With `skip_current`, the starting voxel counts as empty.
  int64_t Step(int pixel, const Volume& volume, int voxel[3], float t_max[3], bool skip_current) const;
  // The direction in grid units (voxel size 1) for `pixel`.
  Eigen::Vector3d GridDirection(int pixel) const;

  VoxelGrid grid_;
  Eigen::Matrix3d world_from_pixel_;
  Eigen::Matrix3d grid_from_pixel_;  // world_from_pixel_ in voxel units, for stepping
  double inverse_width_;             // row = floor((pixel + 0.5) * inverse_width_), exactly
  Eigen::Vector3d centre_grid_;  // camera centre in grid coordinates
  int width_;
  int height_;
  cv::Mat valid_;
  // Structure of arrays: the keys are what footprint scans read, 8 bytes a pixel.
  std::vector<uint64_t> keys_;
  std::vector<TMax> t_max_;
};

}  // namespace raycarve
