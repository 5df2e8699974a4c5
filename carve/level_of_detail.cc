#include "carve/level_of_detail.h"

#include <cmath>

#include <glog/logging.h>

namespace raycarve {
namespace {

// One step of a 3x3x3 dilation of a byte mask, done as three separable passes.
void Dilate(const Eigen::Vector3i& n, std::vector<uint8_t>* mask) {
  const int64_t stride[3] = {1, n.x(), static_cast<int64_t>(n.x()) * n.y()};
  std::vector<uint8_t> source;
  for (int axis = 0; axis < 3; ++axis) {
    source = *mask;
    for (int z = 0; z < n.z(); ++z) {
      for (int y = 0; y < n.y(); ++y) {
        for (int x = 0; x < n.x(); ++x) {
          const int coordinate = axis == 0 ? x : (axis == 1 ? y : z);
          const int64_t index = x + stride[1] * y + stride[2] * z;
          uint8_t value = source[index];
          if (coordinate > 0) value |= source[index - stride[axis]];
          if (coordinate + 1 < n[axis]) value |= source[index + stride[axis]];
          (*mask)[index] = value;
        }
      }
    }
  }
}

}  // namespace

int AutomaticLevels(int resolution) {
  int levels = 1;
  for (int coarsest = resolution; levels < 8 && coarsest % 2 == 0 &&
                                  coarsest / 2 >= kMinAutomaticResolution;
       coarsest /= 2) {
    ++levels;
  }
  return levels;
}

bool LevelResolutions(int resolution, int levels, std::vector<int>* resolutions,
                      std::string* reason) {
  resolutions->clear();
  if (levels == kAutomaticLevels) levels = AutomaticLevels(resolution);
  if (levels < 1 || levels > 8) {
    *reason = "lod_levels must be in [1, 8] (0: automatic), got " + std::to_string(levels);
    return false;
  }
  const int divisor = 1 << (levels - 1);
  if (resolution % divisor != 0) {
    *reason = "with lod_levels " + std::to_string(levels) + " the resolution must be divisible by " +
              std::to_string(divisor) + ", got " + std::to_string(resolution);
    return false;
  }
  if (levels > 1 && resolution / divisor < 4) {
    *reason = "with lod_levels " + std::to_string(levels) + " the coarsest level would have " +
              std::to_string(resolution / divisor) + " voxels along the longest axis (at least 4)";
    return false;
  }
  for (int level = levels - 1; level >= 0; --level) resolutions->push_back(resolution >> level);
  return true;
}

Volume RefineVolume(const Volume& coarse, const VoxelGrid& fine, int band) {
  return RefineRegion(coarse, fine, Eigen::Vector3i::Zero(), band);
}

Volume RefineRegion(const Volume& coarse, const VoxelGrid& fine, const Eigen::Vector3i& offset,
                    int band) {
  const VoxelGrid& grid = coarse.grid();
  const Eigen::Vector3i& n = grid.dimensions();
  const Eigen::Vector3i& m = fine.dimensions();
  CHECK_NEAR(fine.voxel_size() * 2.0, grid.voxel_size(), 1e-12 * grid.voxel_size());
  CHECK((fine.origin() - fine.voxel_size() * offset.cast<double>() - grid.origin()).norm() <=
        1e-9 * grid.voxel_size());
  CHECK((offset.array() >= 0).all() && ((offset + m).array() <= 2 * n.array()).all());
  std::vector<uint8_t> keep(grid.num_voxels());
  for (int64_t index = 0; index < grid.num_voxels(); ++index) keep[index] = coarse.IsSolid(index);
  for (int step = 0; step < band; ++step) Dilate(n, &keep);

  std::vector<uint64_t> solid((fine.num_voxels() + 63) / 64, 0);
  for (int z = 0; z < m.z(); ++z) {
    for (int y = 0; y < m.y(); ++y) {
      const int64_t parent_row =
          grid.Index(Eigen::Vector3i(0, (y + offset.y()) / 2, (z + offset.z()) / 2));
      const int64_t row = fine.Index(Eigen::Vector3i(0, y, z));
      for (int x = 0; x < m.x(); ++x) {
        if (keep[parent_row + (x + offset.x()) / 2]) {
          solid[(row + x) >> 6] |= uint64_t{1} << ((row + x) & 63);
        }
      }
    }
  }
  return Volume(fine, std::move(solid));
}

std::vector<int64_t> DeepInteriorVoxels(const Volume& coarse, const VoxelGrid& fine, int depth) {
  return DeepInteriorRegion(coarse, fine, Eigen::Vector3i::Zero(), depth);
}

std::vector<int64_t> DeepInteriorRegion(const Volume& coarse, const VoxelGrid& fine,
                                        const Eigen::Vector3i& offset, int depth) {
  std::vector<int64_t> deep;
  if (depth <= 0) return deep;
  const VoxelGrid& grid = coarse.grid();
  const Eigen::Vector3i& n = grid.dimensions();
  const Eigen::Vector3i& m = fine.dimensions();
  CHECK_NEAR(fine.voxel_size() * 2.0, grid.voxel_size(), 1e-12 * grid.voxel_size());
  CHECK((offset.array() >= 0).all() && ((offset + m).array() <= 2 * n.array()).all());
  // Within `depth` steps of a carved coarse voxel; the grid's edge counts as carved.
  std::vector<uint8_t> near(grid.num_voxels());
  for (int64_t index = 0; index < grid.num_voxels(); ++index) near[index] = !coarse.IsSolid(index);
  for (int step = 0; step < depth; ++step) Dilate(n, &near);
  for (int z = 0; z < m.z(); ++z) {
    for (int y = 0; y < m.y(); ++y) {
      for (int x = 0; x < m.x(); ++x) {
        const Eigen::Vector3i parent = (Eigen::Vector3i(x, y, z) + offset) / 2;
        if ((parent.array() < depth).any() || (parent.array() >= n.array() - depth).any()) continue;
        if (!near[grid.Index(parent)]) deep.push_back(fine.Index(Eigen::Vector3i(x, y, z)));
      }
    }
  }
  return deep;
}

Volume DilateSolid(const Volume& volume, int band) {
  const VoxelGrid& grid = volume.grid();
  std::vector<uint8_t> keep(grid.num_voxels());
  for (int64_t index = 0; index < grid.num_voxels(); ++index) keep[index] = volume.IsSolid(index);
  for (int step = 0; step < band; ++step) Dilate(grid.dimensions(), &keep);
  std::vector<uint64_t> solid((grid.num_voxels() + 63) / 64, 0);
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    if (keep[index]) solid[index >> 6] |= uint64_t{1} << (index & 63);
  }
  return Volume(grid, std::move(solid));
}

}  // namespace raycarve
