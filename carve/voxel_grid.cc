#include "carve/voxel_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <glog/logging.h>

namespace raycarve {
namespace {

constexpr int kMaxResolution = 4096;

Eigen::Vector3i DimensionsFor(const Eigen::AlignedBox3d& box, int resolution, double* size) {
  const Eigen::Vector3d extent = box.sizes();
  *size = extent.maxCoeff() / resolution;
  Eigen::Vector3i dimensions;
  for (int axis = 0; axis < 3; ++axis) {
    // A hair of tolerance so that the longest axis gets exactly `resolution` voxels.
    dimensions[axis] =
        std::max(1, static_cast<int>(std::ceil(extent[axis] / *size - 1e-9)));
  }
  return dimensions;
}

}  // namespace

VoxelGrid::VoxelGrid(const Eigen::AlignedBox3d& box, int resolution) {
  CHECK(resolution >= 1 && resolution <= kMaxResolution) << "resolution " << resolution;
  CHECK(!box.isEmpty() && (box.sizes().array() > 0.0).all()) << "empty box";
  origin_ = box.min();
  dimensions_ = DimensionsFor(box, resolution, &voxel_size_);
}

Eigen::AlignedBox3d VoxelGrid::Box() const {
  return Eigen::AlignedBox3d(origin_, origin_ + voxel_size_ * dimensions_.cast<double>());
}

VoxelGrid VoxelGrid::Region(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) const {
  CHECK((lo.array() >= 0).all() && (lo.array() < hi.array()).all() &&
        (hi.array() <= dimensions_.array()).all())
      << "region " << lo.transpose() << " .. " << hi.transpose() << " of a grid of "
      << dimensions_.transpose();
  VoxelGrid region = *this;
  region.origin_ = origin_ + voxel_size_ * lo.cast<double>();
  region.dimensions_ = hi - lo;
  return region;
}

Eigen::Vector3i VoxelGrid::Voxel(int64_t index) const {
  const int64_t nx = dimensions_.x(), ny = dimensions_.y();
  return Eigen::Vector3i(static_cast<int>(index % nx),
                         static_cast<int>((index / nx) % ny),
                         static_cast<int>(index / (nx * ny)));
}

Eigen::Vector3i VoxelGrid::VoxelOf(const Eigen::Vector3d& world) const {
  const Eigen::Vector3d grid = (world - origin_) / voxel_size_;
  return Eigen::Vector3i(static_cast<int>(std::floor(grid.x())),
                         static_cast<int>(std::floor(grid.y())),
                         static_cast<int>(std::floor(grid.z())));
}

Eigen::Vector3d VoxelGrid::Centre(const Eigen::Vector3i& voxel) const {
  return origin_ + voxel_size_ * (voxel.cast<double>().array() + 0.5).matrix();
}

bool CheckGridFits(const Eigen::AlignedBox3d& box,
                   int resolution,
                   double bytes_per_voxel,
                   double max_bytes,
                   std::string* reason) {
  if (resolution < 1 || resolution > kMaxResolution) {
    *reason = "resolution must be in [1, " + std::to_string(kMaxResolution) + "], got " +
              std::to_string(resolution);
    return false;
  }
  if (box.isEmpty() || !(box.sizes().array() > 0.0).all()) {
    *reason = "the volume's box is empty";
    return false;
  }
  double size = 0.0;
  const Eigen::Vector3i dimensions = DimensionsFor(box, resolution, &size);
  const double voxels = static_cast<double>(dimensions.x()) * dimensions.y() * dimensions.z();
  const double bytes = voxels * bytes_per_voxel;
  if (bytes > max_bytes) {
    std::ostringstream text;
    text << "a " << dimensions.x() << "x" << dimensions.y() << "x" << dimensions.z()
         << " grid needs about " << bytes / (1024.0 * 1024.0 * 1024.0) << " GiB, above the limit of "
         << max_bytes / (1024.0 * 1024.0 * 1024.0) << " GiB; lower the resolution";
    *reason = text.str();
    return false;
  }
  return true;
}

}  // namespace raycarve
