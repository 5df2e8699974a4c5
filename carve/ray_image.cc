#include "carve/ray_image.h"

#include <cmath>
#include <limits>

#include <glog/logging.h>

namespace raycarve {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

}  // namespace

RayImage::RayImage(const VoxelGrid& grid,
                   const Eigen::Matrix3d& world_from_pixel,
                   const Eigen::Vector3d& centre,
                   int width,
                   int height,
                   const cv::Mat& valid)
    : grid_(grid),
      world_from_pixel_(world_from_pixel),
      grid_from_pixel_(world_from_pixel / grid.voxel_size()),
      inverse_width_(1.0 / width),
      centre_grid_((centre - grid.origin()) / grid.voxel_size()),
      width_(width),
      height_(height),
      valid_(valid) {
  CHECK((grid.dimensions().array() <= 32767).all()) << "grid too large for 16-bit coordinates";
  CHECK(valid.empty() || (valid.type() == CV_8UC1 && valid.cols == width && valid.rows == height));
  keys_.assign(static_cast<size_t>(width) * height, kInactive);
  t_max_.resize(static_cast<size_t>(width) * height);
  for (int pixel = 0; pixel < num_pixels(); ++pixel) InitialiseRay(pixel);
}

Eigen::Vector3d RayImage::Direction(int pixel) const {
  const int row = pixel / width_;
  const int col = pixel - row * width_;
  return world_from_pixel_ * Eigen::Vector3d(col + 0.5, row + 0.5, 1.0);
}

Eigen::Vector3d RayImage::GridDirection(int pixel) const {
  // No integer division on this hot path: (pixel + 0.5) / width is at least 0.5 / width away from
  // an integer, far beyond the rounding of the product.
  const int row = static_cast<int>((pixel + 0.5) * inverse_width_);
  const int col = pixel - row * width_;
  return grid_from_pixel_ * Eigen::Vector3d(col + 0.5, row + 0.5, 1.0);
}

void RayImage::InitialiseRay(int pixel) {
  keys_[pixel] = kInactive;
  float* t_max = t_max_[pixel].axis;
  if (!valid_.empty() && valid_.data[pixel] == 0) return;
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
    if (d[axis] > 0.0) {
      t_max[axis] = static_cast<float>((voxel[axis] + 1 - o[axis]) / d[axis]);
    } else if (d[axis] < 0.0) {
      t_max[axis] = static_cast<float>((voxel[axis] - o[axis]) / d[axis]);
    } else {
      t_max[axis] = std::numeric_limits<float>::infinity();
    }
  }
  keys_[pixel] = Key(voxel);
}

void RayImage::Initialise(const Volume& volume) {
  for (int pixel = 0; pixel < num_pixels(); ++pixel) {
    InitialiseRay(pixel);
    Advance(pixel, volume);
  }
}

int64_t RayImage::Step(int pixel, const Volume& volume, int voxel[3], float t_max[3],
                       bool skip_current) const {
  const Eigen::Vector3i& n = grid_.dimensions();
  int64_t index = voxel[0] + static_cast<int64_t>(n.x()) * (voxel[1] + static_cast<int64_t>(n.y()) * voxel[2]);
  if (!skip_current && volume.IsSolid(index)) return index;
  const Eigen::Vector3d d = GridDirection(pixel);
  int step[3];
  float t_delta[3];
  const int64_t stride[3] = {1, n.x(), static_cast<int64_t>(n.x()) * n.y()};
  for (int axis = 0; axis < 3; ++axis) {
    step[axis] = d[axis] > 0.0 ? 1 : -1;
    t_delta[axis] = 1.0f / std::abs(static_cast<float>(d[axis]));  // inf along an axis plane
  }
  while (true) {
    const int axis = t_max[0] < t_max[1] ? (t_max[0] < t_max[2] ? 0 : 2)
                                         : (t_max[1] < t_max[2] ? 1 : 2);
    voxel[axis] += step[axis];
    if (voxel[axis] < 0 || voxel[axis] >= n[axis]) return kNoVoxel;
    t_max[axis] += t_delta[axis];
    index += step[axis] * stride[axis];
    if (volume.IsSolid(index)) return index;
  }
}

int64_t RayImage::Advance(int pixel, const Volume& volume) {
  const uint64_t key = keys_[pixel];
  if (key == kInactive) return kNoVoxel;
  int voxel[3] = {static_cast<int>(key & 0xffff), static_cast<int>((key >> 16) & 0xffff),
                  static_cast<int>((key >> 32) & 0xffff)};
  const int64_t index = Step(pixel, volume, voxel, t_max_[pixel].axis, /*skip_current=*/false);
  keys_[pixel] = index == kNoVoxel ? kInactive : Key(Eigen::Vector3i(voxel[0], voxel[1], voxel[2]));
  return index;
}

int64_t RayImage::PeekBeyondCurrent(int pixel, const Volume& volume) const {
  const uint64_t key = keys_[pixel];
  if (key == kInactive) return kNoVoxel;
  int voxel[3] = {static_cast<int>(key & 0xffff), static_cast<int>((key >> 16) & 0xffff),
                  static_cast<int>((key >> 32) & 0xffff)};
  float t_max[3] = {t_max_[pixel].axis[0], t_max_[pixel].axis[1], t_max_[pixel].axis[2]};
  return Step(pixel, volume, voxel, t_max, /*skip_current=*/true);
}

}  // namespace raycarve
