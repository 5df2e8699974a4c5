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
      centre_grid_((centre - grid.origin()) / grid.voxel_size()),
      width_(width),
      height_(height),
      valid_(valid) {
  CHECK((grid.dimensions().array() <= 32767).all()) << "grid too large for 16-bit coordinates";
  CHECK(valid.empty() || (valid.type() == CV_8UC1 && valid.cols == width && valid.rows == height));
  rays_.resize(static_cast<size_t>(width) * height);
  for (int pixel = 0; pixel < num_pixels(); ++pixel) InitialiseRay(pixel);
}

Eigen::Vector3d RayImage::Direction(int pixel) const {
  const int row = pixel / width_;
  const int col = pixel - row * width_;
  return world_from_pixel_ * Eigen::Vector3d(col + 0.5, row + 0.5, 1.0);
}

Eigen::Vector3d RayImage::GridDirection(int pixel) const {
  return Direction(pixel) / grid_.voxel_size();
}

void RayImage::InitialiseRay(int pixel) {
  RayState& ray = rays_[pixel];
  ray.active = 0;
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
  for (int axis = 0; axis < 3; ++axis) {
    int coordinate = static_cast<int>(std::floor(entry[axis]));
    coordinate = std::clamp(coordinate, 0, n[axis] - 1);
    ray.voxel[axis] = static_cast<int16_t>(coordinate);
    if (d[axis] > 0.0) {
      ray.t_max[axis] = static_cast<float>((coordinate + 1 - o[axis]) / d[axis]);
    } else if (d[axis] < 0.0) {
      ray.t_max[axis] = static_cast<float>((coordinate - o[axis]) / d[axis]);
    } else {
      ray.t_max[axis] = std::numeric_limits<float>::infinity();
    }
  }
  ray.active = 1;
}

void RayImage::Initialise(const Volume& volume) {
  for (int pixel = 0; pixel < num_pixels(); ++pixel) {
    InitialiseRay(pixel);
    Advance(pixel, volume);
  }
}

int64_t RayImage::Advance(int pixel, const Volume& volume) {
  RayState& ray = rays_[pixel];
  if (!ray.active) return kNoVoxel;
  const Eigen::Vector3i& n = grid_.dimensions();
  int64_t index = grid_.Index(Eigen::Vector3i(ray.voxel[0], ray.voxel[1], ray.voxel[2]));
  if (volume.IsSolid(index)) return index;
  const Eigen::Vector3d d = GridDirection(pixel);
  int step[3];
  float t_delta[3];
  int64_t stride[3] = {1, n.x(), static_cast<int64_t>(n.x()) * n.y()};
  for (int axis = 0; axis < 3; ++axis) {
    step[axis] = d[axis] > 0.0 ? 1 : -1;
    t_delta[axis] = d[axis] == 0.0 ? std::numeric_limits<float>::infinity()
                                   : static_cast<float>(1.0 / std::abs(d[axis]));
  }
  while (true) {
    const int axis = ray.t_max[0] < ray.t_max[1] ? (ray.t_max[0] < ray.t_max[2] ? 0 : 2)
                                                 : (ray.t_max[1] < ray.t_max[2] ? 1 : 2);
    const int next = ray.voxel[axis] + step[axis];
    if (next < 0 || next >= n[axis]) {
      ray.active = 0;
      return kNoVoxel;
    }
    ray.voxel[axis] = static_cast<int16_t>(next);
    ray.t_max[axis] += t_delta[axis];
    index += step[axis] * stride[axis];
    if (volume.IsSolid(index)) return index;
  }
}

}  // namespace raycarve
