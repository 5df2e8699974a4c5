#include "carve/ray_image.h"

#include <thread>

#include <algorithm>
#include <cmath>
#include <limits>

#include <glog/logging.h>

namespace raycarve {

inline Eigen::Vector3d RayImage::GridDirection(int pixel) const {
  // No integer division on this hot path: (pixel + 0.5) / width is at least 0.5 / width away from
  // an integer, far beyond the rounding of the product.
  const int row = static_cast<int>((pixel + 0.5) * inverse_width_);
  const int col = pixel - row * width_;
  return grid_from_pixel_ * Eigen::Vector3d(col + 0.5, row + 0.5, 1.0);
}

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr int kZero[3] = {0, 0, 0};

// Bits needed for coordinates 0 .. n-1.
int CoordinateBits(int n) {
  int bits = 0;
  while ((int64_t{1} << bits) < n) ++bits;
  return bits;
}

}  // namespace

bool RayImage::KeyBitsFit(const Eigen::Vector3i& dimensions) {
  return (dimensions.array() >= 1).all() &&
         CoordinateBits(dimensions.x()) + CoordinateBits(dimensions.y()) +
                 CoordinateBits(dimensions.z()) <=
             31;
}

RayImage::RayImage(const VoxelGrid& grid,
                   const Eigen::Matrix3d& world_from_pixel,
                   const Eigen::Vector3d& centre,
                   int width,
                   int height,
                   const cv::Mat& valid)
    : grid_(grid),
      world_from_pixel_(world_from_pixel),
      grid_from_pixel_(world_from_pixel / grid.voxel_size()),
      pixel_from_grid_(grid_from_pixel_.inverse()),
      inverse_width_(1.0 / width),
      centre_grid_((centre - grid.origin()) / grid.voxel_size()),
      width_(width),
      height_(height),
      valid_(valid) {
  const Eigen::Vector3i& n = grid.dimensions();
  CHECK(KeyBitsFit(n)) << "grid " << n.transpose() << " too large for 31-bit ray keys";
  CHECK(valid.empty() || (valid.type() == CV_8UC1 && valid.cols == width && valid.rows == height &&
                          valid.isContinuous()));
  shift_y_ = CoordinateBits(n.x());
  shift_z_ = shift_y_ + CoordinateBits(n.y());
  mask_x_ = (uint32_t{1} << shift_y_) - 1;
  mask_y_ = (uint32_t{1} << (shift_z_ - shift_y_)) - 1;
  if (!valid.empty()) valid_pixels_ = valid_.ptr<uint8_t>(0);
  keys_.assign(static_cast<size_t>(width) * height, kInactive);
  const int64_t voxels = grid.num_voxels();
  if (voxels <= 32 * static_cast<int64_t>(width) * height) arrived_.assign((voxels + 63) / 64, 0);
}

Eigen::Vector3d RayImage::Direction(int pixel) const {
  const int row = pixel / width_;
  const int col = pixel - row * width_;
  return world_from_pixel_ * Eigen::Vector3d(col + 0.5, row + 0.5, 1.0);
}



void RayImage::InitialiseRay(int pixel) {
  keys_[pixel] = kInactive;
  if (valid_pixels_ != nullptr && valid_pixels_[pixel] == 0) return;
  const Eigen::Vector3d d = GridDirection(pixel);
  const Eigen::Vector3d& o = centre_grid_;
  const Eigen::Vector3i& n = grid_.dimensions();
  // Slab test against the grid box [0, n] in grid coordinates.
  double t_enter = 0.0, t_exit = kInfinity;
  for (int axis = 0; axis < 3; ++axis) {
    if (d[axis] == 0.0) {
      if (o[axis] < 0.0 || o[axis] > n[axis]) return;
      continue;
    }
    double t0 = (0.0 - o[axis]) / d[axis];
    double t1 = (n[axis] - o[axis]) / d[axis];
    if (t0 > t1) std::swap(t0, t1);
    t_enter = std::max(t_enter, t0);
    t_exit = std::min(t_exit, t1);
  }
  if (!(t_enter < t_exit)) return;
  // The voxel holding the entry point; the clamp settles points that round onto an outer face.
  const Eigen::Vector3d entry = o + t_enter * d;
  Eigen::Vector3i voxel;
  for (int axis = 0; axis < 3; ++axis) {
    voxel[axis] = std::clamp(static_cast<int>(std::floor(entry[axis])), 0, n[axis] - 1);
  }
  keys_[pixel] = Key(voxel);
}

std::vector<uint8_t> RayImage::ReachableTiles(const BlockOccupancy& blocks) const {
  constexpr int kSize = BlockOccupancy::kSize;
  // Pixels to spare around a block's bounding box: far beyond the rounding of the projection
  // and of the rays' stepping.
  constexpr double kSlackPixels = 1.0;
  const int across = tiles_across(), down = (height_ + kTileSize - 1) >> kTileShift;
  std::vector<uint8_t> tiles(static_cast<size_t>(across) * down, 0);
  const Eigen::Vector3i& n = grid_.dimensions();
  for (const Eigen::Vector3i& block : blocks.boundary()) {
    const Eigen::Vector3i low = block * kSize;
    const Eigen::Vector3i high = (low.array() + kSize).min(n.array());
    double x_min = INFINITY, x_max = -INFINITY, y_min = INFINITY, y_max = -INFINITY;
    bool in_front = true;
    for (int c = 0; c < 8 && in_front; ++c) {
      const Eigen::Vector3d corner((c & 1) ? high.x() : low.x(), (c & 2) ? high.y() : low.y(),
                                   (c & 4) ? high.z() : low.z());
      const Eigen::Vector3d h = pixel_from_grid_ * (corner - centre_grid_);
      // A block reaching the camera's plane may be seen anywhere in the photo.
      in_front = h.z() > 1e-9 * h.head<2>().norm();
      x_min = std::min(x_min, h.x() / h.z());
      x_max = std::max(x_max, h.x() / h.z());
      y_min = std::min(y_min, h.y() / h.z());
      y_max = std::max(y_max, h.y() / h.z());
    }
    if (!in_front) {
      std::fill(tiles.begin(), tiles.end(), 1);
      return tiles;
    }
    // Pixel centres (col + 0.5, row + 0.5) within the box, with slack, clipped to the photo.
    const double col_low = std::max(0.0, std::floor(x_min - 0.5 - kSlackPixels));
    const double col_high = std::min(width_ - 1.0, std::ceil(x_max - 0.5 + kSlackPixels));
    const double row_low = std::max(0.0, std::floor(y_min - 0.5 - kSlackPixels));
    const double row_high = std::min(height_ - 1.0, std::ceil(y_max - 0.5 + kSlackPixels));
    if (!(col_low <= col_high && row_low <= row_high)) continue;  // beside the photo
    for (int row = static_cast<int>(row_low) >> kTileShift;
         row <= static_cast<int>(row_high) >> kTileShift; ++row) {
      for (int col = static_cast<int>(col_low) >> kTileShift;
           col <= static_cast<int>(col_high) >> kTileShift; ++col) {
        tiles[static_cast<size_t>(row) * across + col] = 1;
      }
    }
  }
  return tiles;
}

void RayImage::Initialise(const Volume& volume, const BlockOccupancy* blocks, int num_threads) {
  CHECK(volume.grid().dimensions() == grid_.dimensions());
  CHECK(blocks == nullptr ||
        (blocks->dimensions().array() ==
         (grid_.dimensions().array() + (BlockOccupancy::kSize - 1)) / BlockOccupancy::kSize)
            .all());
  if (blocks == nullptr) {
    for (int pixel = 0; pixel < num_pixels(); ++pixel) {
      InitialiseRay(pixel);
      Advance(pixel, volume);
    }
    return;
  }
  const std::vector<uint8_t> tiles = ReachableTiles(*blocks);
  const int across = tiles_across();
  // Rows [first, last): each ray writes only its own key.
  auto trace_rows = [&](int first, int last) {
    for (int row = first; row < last; ++row) {
      const uint8_t* row_tiles = tiles.data() + static_cast<size_t>(row >> kTileShift) * across;
      for (int col = 0, pixel = row * width_; col < width_; ++col, ++pixel) {
        if (row_tiles[col >> kTileShift] == 0) {
          keys_[pixel] = kInactive;
          continue;
        }
        InitialiseRay(pixel);
        if (keys_[pixel] != kInactive) keys_[pixel] = FirstSolid(pixel, volume, *blocks);
      }
    }
  };
  if (num_threads > 1) {
    const int per_thread = (height_ + num_threads - 1) / num_threads;
    std::vector<std::thread> workers;
    for (int t = 0; t < num_threads; ++t) {
      const int first = t * per_thread, last = std::min(height_, first + per_thread);
      if (first >= last) break;
      workers.emplace_back(trace_rows, first, last);
    }
    for (std::thread& worker : workers) worker.join();
  } else {
    trace_rows(0, height_);
  }
  // The arrivals, bits shared between rays, are marked after the rays are traced.
  for (int pixel = 0; pixel < num_pixels(); ++pixel) {
    if (keys_[pixel] != kInactive) MarkArrival(grid_.Index(Unpack(keys_[pixel])));
  }
}

namespace {

// One axis of an Amanatides-Woo traversal: the ray parameter where the ray leaves the current
// voxel through that axis's far face (infinite along an axis plane: that axis never steps), the
// parameter length of one voxel, the step, its index stride and the coordinate that means the
// ray has left the region.
struct WalkAxis {
  double t_max;
  double t_delta;
  int step;
  int end;
  int64_t index_step;
};

// The axis's state for a ray of direction component `d` in a voxel whose low and high faces along
// it are `face_low` and `face_high` (offsets from the camera centre); `stride` is the axis's
// index stride and [lo, hi) the region's coordinates along it.
inline WalkAxis StartAxis(double d, double face_low, double face_high, int64_t stride, int lo,
                          int hi) {
  const double inverse = 1.0 / d;
  const bool up = d > 0.0;
  return {d == 0.0 ? kInfinity : (up ? face_high : face_low) * inverse, std::abs(inverse),
          up ? 1 : -1, up ? hi : lo - 1, up ? stride : -stride};
}

// The hottest loop of ray-cast carving: from voxel (x, y, z) at `index`, not solid, steps until a
// solid voxel (its index returned; x, y, z updated) or the edge of the region (kNoVoxel; x, y, z
// the first voxel outside it). Scalars rather than arrays indexed by the chosen axis, so that
// the state stays in registers.
inline __attribute__((always_inline)) int64_t Walk(const uint64_t* solid, int64_t index, int* x,
                                                   int* y, int* z, WalkAxis ax, WalkAxis ay,
                                                   WalkAxis az) {
  int vx = *x, vy = *y, vz = *z;
  while (true) {
    if (ax.t_max < ay.t_max && ax.t_max < az.t_max) {
      vx += ax.step;
      if (vx == ax.end) break;
      ax.t_max += ax.t_delta;
      index += ax.index_step;
    } else if (!(ax.t_max < ay.t_max) && ay.t_max < az.t_max) {
      vy += ay.step;
      if (vy == ay.end) break;
      ay.t_max += ay.t_delta;
      index += ay.index_step;
    } else {
      vz += az.step;
      if (vz == az.end) break;
      az.t_max += az.t_delta;
      index += az.index_step;
    }
    if (((solid[index >> 6] >> (index & 63)) & 1) != 0) {
      *x = vx;
      *y = vy;
      *z = vz;
      return index;
    }
  }
  *x = vx;
  *y = vy;
  *z = vz;
  return RayImage::kNoVoxel;
}

}  // namespace

int64_t RayImage::Step(int pixel,
                       const uint64_t* solid,
                       int voxel[3],
                       bool skip_current,
                       const int lo[3],
                       const int hi[3]) const {
  const Eigen::Vector3i& n = grid_.dimensions();
  const int64_t stride_y = n.x(), stride_z = static_cast<int64_t>(n.x()) * n.y();
  int x = voxel[0], y = voxel[1], z = voxel[2];
  const int64_t index = x + stride_y * y + stride_z * z;
  if (!skip_current && ((solid[index >> 6] >> (index & 63)) & 1) != 0) return index;
  const Eigen::Vector3d d = GridDirection(pixel);
  const Eigen::Vector3d& c = centre_grid_;
  const int64_t reached =
      Walk(solid, index, &x, &y, &z, StartAxis(d.x(), x - c.x(), (x + 1) - c.x(), 1, lo[0], hi[0]),
           StartAxis(d.y(), y - c.y(), (y + 1) - c.y(), stride_y, lo[1], hi[1]),
           StartAxis(d.z(), z - c.z(), (z + 1) - c.z(), stride_z, lo[2], hi[2]));
  voxel[0] = x;
  voxel[1] = y;
  voxel[2] = z;
  return reached;
}

void RayImage::AdvanceFromCarved(const Eigen::Vector3i& voxel,
                                 const PixelRef* begin,
                                 const PixelRef* end,
                                 const Volume& volume,
                                 std::vector<int64_t>* reached) {
  const Eigen::Vector3i& n = grid_.dimensions();
  const int64_t stride_y = n.x(), stride_z = static_cast<int64_t>(n.x()) * n.y();
  const int64_t start = voxel.x() + stride_y * voxel.y() + stride_z * voxel.z();
  const uint64_t* solid = volume.solid_bits().data();
  DCHECK(((solid[start >> 6] >> (start & 63)) & 1) == 0) << "AdvanceFromCarved: voxel is solid";
  // The voxel's faces as offsets from the camera centre, as Step works them out per ray.
  const Eigen::Vector3d& c = centre_grid_;
  const double low_x = voxel.x() - c.x(), high_x = (voxel.x() + 1) - c.x();
  const double low_y = voxel.y() - c.y(), high_y = (voxel.y() + 1) - c.y();
  const double low_z = voxel.z() - c.z(), high_z = (voxel.z() + 1) - c.z();
  for (const PixelRef* ref = begin; ref != end; ++ref) {
    const int pixel = static_cast<int>(ref->pixel);
    DCHECK_EQ(keys_[pixel], Key(voxel));
    const Eigen::Vector3d d = GridDirection(pixel);
    int x = voxel.x(), y = voxel.y(), z = voxel.z();
    const int64_t index =
        Walk(solid, start, &x, &y, &z, StartAxis(d.x(), low_x, high_x, 1, 0, n.x()),
             StartAxis(d.y(), low_y, high_y, stride_y, 0, n.y()),
             StartAxis(d.z(), low_z, high_z, stride_z, 0, n.z()));
    if (index == kNoVoxel) {
      keys_[pixel] = kInactive;
      continue;
    }
    keys_[pixel] = Key(Eigen::Vector3i(x, y, z));
    MarkArrival(index);
    reached->push_back(index);
  }
}

bool RayImage::SkipEmptyBlocks(int pixel, const BlockOccupancy& blocks, int voxel[3]) const {
  constexpr int kShift = BlockOccupancy::kShift;
  constexpr int kSize = BlockOccupancy::kSize;
  const Eigen::Vector3i& n = grid_.dimensions();
  const int bx = voxel[0] >> kShift, by = voxel[1] >> kShift, bz = voxel[2] >> kShift;
  const Eigen::Vector3i& nb = blocks.dimensions();
  const int64_t block_stride_y = nb.x(), block_stride_z = static_cast<int64_t>(nb.x()) * nb.y();
  int64_t block = bx + block_stride_y * by + block_stride_z * bz;
  if (blocks.IsOccupied(block)) return true;
  const Eigen::Vector3d d = GridDirection(pixel);
  // Step's traversal on a grid of voxels kSize wide, the state per axis. The ray leaves the
  // grid at t_exit: the last block along an axis may be partial (the grid ends at n, not at a
  // block edge), so leaving the blocks is not enough.
  double t_exit = kInfinity;
  int entered[3] = {bx, by, bz}, step[3], end[3];
  double t_max[3], t_delta[3];
  int64_t index_step[3];
  const int64_t stride[3] = {1, block_stride_y, block_stride_z};
  for (int axis = 0; axis < 3; ++axis) {
    const bool up = d[axis] > 0.0;
    if (d[axis] != 0.0) {
      t_exit = std::min(t_exit, ((up ? n[axis] : 0) - centre_grid_[axis]) / d[axis]);
    }
    t_max[axis] = d[axis] == 0.0
                      ? kInfinity
                      : ((entered[axis] + (up ? 1 : 0)) * kSize - centre_grid_[axis]) / d[axis];
    t_delta[axis] = kSize / std::abs(d[axis]);
    step[axis] = up ? 1 : -1;
    index_step[axis] = up ? stride[axis] : -stride[axis];
    // Leaving the blocks (or the grid, at t_exit) ends the search.
    end[axis] = up ? nb[axis] : -1;
  }
  // The axis and parameter of the last step: where the ray enters the block it stops in. Ties go
  // to the later axis.
  int axis;
  double t;
  do {
    axis = t_max[0] < t_max[1] ? (t_max[0] < t_max[2] ? 0 : 2) : (t_max[1] < t_max[2] ? 1 : 2);
    t = t_max[axis];
    entered[axis] += step[axis];
    if (entered[axis] == end[axis] || t >= t_exit) return false;
    t_max[axis] += t_delta[axis];
    block += index_step[axis];
  } while (!blocks.IsOccupied(block));
  // The voxel where the ray enters the block: on the entered face along `axis`, and where the ray
  // is at that moment along the others (kept inside the block against rounding).
  for (int other = 0; other < 3; ++other) {
    const int first = entered[other] * kSize;
    const int last = std::min(first + kSize, n[other]) - 1;
    if (other == axis) {
      voxel[other] = d[other] > 0.0 ? first : last;
    } else {
      const int at = static_cast<int>(std::floor(centre_grid_[other] + t * d[other]));
      voxel[other] = std::clamp(at, first, last);
    }
  }
  return true;
}

uint32_t RayImage::FirstSolid(int pixel, const Volume& volume, const BlockOccupancy& blocks) const {
  constexpr int kShift = BlockOccupancy::kShift;
  constexpr int kSize = BlockOccupancy::kSize;
  const Eigen::Vector3i& n = grid_.dimensions();
  const Eigen::Vector3i start = Unpack(keys_[pixel]);
  int voxel[3] = {start.x(), start.y(), start.z()};
  // Each round moves to a later block along the ray, so the loop ends.
  while (true) {
    if (!SkipEmptyBlocks(pixel, blocks, voxel)) return kInactive;
    int lo[3], hi[3];
    for (int axis = 0; axis < 3; ++axis) {
      lo[axis] = (voxel[axis] >> kShift) << kShift;
      hi[axis] = std::min(lo[axis] + kSize, n[axis]);
    }
    if (Step(pixel, volume.solid_bits().data(), voxel, /*skip_current=*/false, lo, hi) !=
        kNoVoxel) {
      return Key(Eigen::Vector3i(voxel[0], voxel[1], voxel[2]));
    }
    for (int axis = 0; axis < 3; ++axis) {
      if (voxel[axis] < 0 || voxel[axis] >= n[axis]) return kInactive;  // left the grid
    }
  }
}

int64_t RayImage::StepFromCurrent(int pixel, const Volume& volume, bool skip_current,
                                  int voxel[3]) const {
  const uint32_t key = keys_[pixel];
  if (key == kInactive) return kNoVoxel;
  const Eigen::Vector3i start = Unpack(key);
  for (int axis = 0; axis < 3; ++axis) voxel[axis] = start[axis];
  const Eigen::Vector3i& n = grid_.dimensions();
  const int end[3] = {n.x(), n.y(), n.z()};
  return Step(pixel, volume.solid_bits().data(), voxel, skip_current, kZero, end);
}

int64_t RayImage::Advance(int pixel, const Volume& volume) {
  if (keys_[pixel] == kInactive) return kNoVoxel;
  int voxel[3];
  const int64_t index = StepFromCurrent(pixel, volume, /*skip_current=*/false, voxel);
  if (index == kNoVoxel) {
    keys_[pixel] = kInactive;
  } else {
    keys_[pixel] = Key(Eigen::Vector3i(voxel[0], voxel[1], voxel[2]));
    MarkArrival(index);
  }
  return index;
}

int64_t RayImage::PeekBeyondCurrent(int pixel, const Volume& volume) const {
  int voxel[3];
  return StepFromCurrent(pixel, volume, /*skip_current=*/true, voxel);
}

}  // namespace raycarve
