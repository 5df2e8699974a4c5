#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "carve/block_occupancy.h"
#include "carve/visibility.h"
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
// Memory: 4 bytes per pixel, the current voxel's coordinates packed into one 32-bit key. Nothing
// else is stored: the direction follows from the pixel, and the traversal state (the ray
// parameter of the next boundary per axis) from the direction and the current voxel, so both are
// recomputed when a ray is stepped. Recomputing is also exact where accumulating tMax in floats
// drifts. The key packs each axis in as many bits as its dimension needs; the three together
// must fit in 31 bits (KeyBitsFit), e.g. 1024 x 1024 x 1024 or 4096 x 4096 x 128.
class RayImage {
 public:
  static constexpr int64_t kNoVoxel = -1;

  // Whether a grid's voxel coordinates fit a ray's 31-bit key.
  static bool KeyBitsFit(const Eigen::Vector3i& dimensions);

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

  // Moves every ray to the first solid voxel of `volume` along it (until then every ray is
  // gone). With `blocks` (made from `volume`), empty blocks are crossed a block at a time: the
  // same voxels (up to rays through exact block edges, which may start in either voxel they
  // touch), at a fraction of the steps where much of the volume is empty; and the pixels of
  // tiles that no boundary block projects onto are not traced at all (their rays miss every
  // occupied block): most of a photo, where the object is small in it or the box ends.
  // With `blocks`, `num_threads` > 1 splits the pixels among that many threads (the same rays).
  void Initialise(const Volume& volume, const BlockOccupancy* blocks = nullptr,
                  int num_threads = 1);

  int64_t CurrentVoxel(int pixel) const {
    const uint32_t key = keys_[pixel];
    return key == kInactive ? kNoVoxel : grid_.Index(Unpack(key));
  }

  // A voxel's key: what keys() holds for a ray whose current voxel it is. Comparing keys is how
  // a footprint is scanned without decoding every ray.
  uint32_t Key(const Eigen::Vector3i& voxel) const {
    return static_cast<uint32_t>(voxel.x()) | static_cast<uint32_t>(voxel.y()) << shift_y_ |
           static_cast<uint32_t>(voxel.z()) << shift_z_;
  }
  // Per pixel, row-major: the current voxel's key, or a value no voxel has when the ray is gone.
  const uint32_t* keys() const { return keys_.data(); }

  // Steps the ray at `pixel` until its current voxel is solid in `volume` or it leaves the box
  // (then kNoVoxel). Returns the new current voxel. A ray already at a solid voxel stays.
  // Cost: one step per voxel passed (Amanatides-Woo).
  int64_t Advance(int pixel, const Volume& volume);
  // Advance for the rays at the pixels of `begin` .. `end` (their `pixel` fields), all of whose
  // current voxel is `voxel`, no longer solid in `volume` (carved): appends each solid voxel
  // reached to `reached`. The same rays as Advance one by one, at less cost: the start is known
  // and the voxel's faces are worked out once for all of them.
  void AdvanceFromCarved(const Eigen::Vector3i& voxel,
                         const PixelRef* begin,
                         const PixelRef* end,
                         const Volume& volume,
                         std::vector<int64_t>* reached);

  // Whether some ray of this image has ended in `voxel` since Initialise. For a solid voxel this
  // is exactly whether some ray ends in it now: a ray leaves a voxel only once it is carved, so a
  // bit set on arrival never needs clearing while the voxel is solid. Where this image keeps no
  // arrival bits (see HasArrivalBits) every voxel answers true. Footprint scans use it to skip
  // the views that cannot see a voxel.
  bool MayEndIn(int64_t voxel) const {
    return arrived_.empty() || ((arrived_[voxel >> 6] >> (voxel & 63)) & 1) != 0;
  }
  // Arrival bits are kept when they take no more memory than the rays (one bit a voxel against
  // 4 bytes a pixel: grids of at most 32 voxels a pixel).
  bool HasArrivalBits() const { return !arrived_.empty(); }

  // The voxel the ray at `pixel` would reach if its current voxel were carved: the first solid
  // voxel of `volume` beyond it, or kNoVoxel. Changes nothing.
  int64_t PeekBeyondCurrent(int pixel, const Volume& volume) const;

  // The ray parameter convention: world point = centre + t * Direction(pixel).
  Eigen::Vector3d Direction(int pixel) const;

  size_t MemoryBytes() const {
    return keys_.capacity() * sizeof(uint32_t) + arrived_.capacity() * sizeof(uint64_t);
  }

 private:
  static constexpr uint32_t kInactive = ~uint32_t{0};
  Eigen::Vector3i Unpack(uint32_t key) const {
    return Eigen::Vector3i(static_cast<int>(key & mask_x_),
                           static_cast<int>((key >> shift_y_) & mask_y_),
                           static_cast<int>(key >> shift_z_));
  }

  void InitialiseRay(int pixel);
  // Per tile of kTileSize x kTileSize pixels (row-major, tiles_across() wide), whether a ray
  // through one of its pixels may hit an occupied block of `blocks`: the tiles under each
  // boundary block's projected corners' bounding box, with a pixel to spare (all tiles where a
  // block reaches the camera's plane).
  static constexpr int kTileShift = 3;
  static constexpr int kTileSize = 1 << kTileShift;
  int tiles_across() const { return (width_ + kTileSize - 1) >> kTileShift; }
  std::vector<uint8_t> ReachableTiles(const BlockOccupancy& blocks) const;
  void MarkArrival(int64_t voxel) {
    if (!arrived_.empty()) arrived_[voxel >> 6] |= uint64_t{1} << (voxel & 63);
  }
  // Steps from `voxel` (updated in place) until a solid voxel (returned, its index) or the edge
  // of the region [lo, hi) of voxel coordinates (kNoVoxel; `voxel` is then the first voxel
  // outside it). With `skip_current`, the starting voxel counts as empty.
  int64_t Step(int pixel,
               const uint64_t* solid,
               int voxel[3],
               bool skip_current,
               const int lo[3],
               const int hi[3]) const;
  // Step over the whole grid from the pixel's current voxel (kNoVoxel when the ray is inactive);
  // `voxel` ends where Step leaves it.
  int64_t StepFromCurrent(int pixel, const Volume& volume, bool skip_current, int voxel[3]) const;
  // From `voxel`, crosses empty blocks until the ray enters an occupied one (true; `voxel` is
  // then where it enters) or leaves the grid (false).
  bool SkipEmptyBlocks(int pixel, const BlockOccupancy& blocks, int voxel[3]) const;
  // The key of the first solid voxel from the ray's current (entry) voxel, or kInactive.
  uint32_t FirstSolid(int pixel, const Volume& volume, const BlockOccupancy& blocks) const;
  // The direction in grid units (voxel size 1) for `pixel`.
  Eigen::Vector3d GridDirection(int pixel) const;

  VoxelGrid grid_;
  Eigen::Matrix3d world_from_pixel_;
  Eigen::Matrix3d grid_from_pixel_;  // world_from_pixel_ in voxel units, for stepping
  Eigen::Matrix3d pixel_from_grid_;  // its inverse: grid offsets from the centre to pixels
  double inverse_width_;             // row = floor((pixel + 0.5) * inverse_width_), exactly
  Eigen::Vector3d centre_grid_;  // camera centre in grid coordinates
  int width_;
  int height_;
  cv::Mat valid_;
  const uint8_t* valid_pixels_ = nullptr;  // valid_'s pixels (it is continuous), or none
  int shift_y_;  // key = x | y << shift_y_ | z << shift_z_
  int shift_z_;
  uint32_t mask_x_;
  uint32_t mask_y_;
  std::vector<uint32_t> keys_;
  std::vector<uint64_t> arrived_;  // per voxel, set when a ray ends there (MayEndIn)
};

}  // namespace raycarve
