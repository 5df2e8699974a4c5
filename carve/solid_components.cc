// IncrementalCarver's removal of solid components: specks, and floaters without sparse points.
#include "carve/incremental_carver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include <glog/logging.h>

#include "carve/free_space.h"
#include "carve/item_buffer_visibility.h"
#include "carve/layered_depth_visibility.h"
#include "carve/patch_correlation.h"
#include "carve/ray_image.h"


namespace raycarve {

namespace {

// Calls visit(voxels) for each 26-connected component of `volume`'s solid voxels (in the order of
// their first voxel's index; each component's voxels in breadth-first order from it).
template <typename Visit>
void ForEachSolidComponent(const Volume& volume, Visit visit) {
  const VoxelGrid& grid = volume.grid();
  const Eigen::Vector3i& n = grid.dimensions();
  std::vector<uint64_t> seen((grid.num_voxels() + 63) / 64, 0);
  const auto mark = [&seen](int64_t i) {
    const bool was = (seen[i >> 6] >> (i & 63)) & 1;
    seen[i >> 6] |= uint64_t{1} << (i & 63);
    return !was;
  };
  std::vector<int64_t> component;
  for (int64_t start = 0; start < grid.num_voxels(); ++start) {
    if (!volume.IsSolid(start) || !mark(start)) continue;
    component.assign(1, start);
    for (size_t k = 0; k < component.size(); ++k) {
      const Eigen::Vector3i voxel = grid.Voxel(component[k]);
      for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const Eigen::Vector3i next = voxel + Eigen::Vector3i(dx, dy, dz);
            if ((next.array() < 0).any() || (next.array() >= n.array()).any()) continue;
            const int64_t index = grid.Index(next);
            if (volume.IsSolid(index) && mark(index)) component.push_back(index);
          }
        }
      }
    }
    visit(component);
  }
}

}  // namespace

int64_t IncrementalCarver::RemoveSmallComponents(int64_t min_voxels) {
  std::vector<int64_t> small;
  ForEachSolidComponent(volume_, [&](const std::vector<int64_t>& component) {
    if (static_cast<int64_t>(component.size()) < min_voxels) {
      small.insert(small.end(), component.begin(), component.end());
    }
  });
  for (int64_t voxel : small) CarveAndQueue(voxel);
  return static_cast<int64_t>(small.size());
}

int64_t IncrementalCarver::RemoveUnsupportedComponents(const std::vector<SurfacePoint>& points,
                                                       double min_expected,
                                                       int64_t* components,
                                                       double* largest_expected) {
  const VoxelGrid& grid = volume_.grid();
  // Which points lie within one voxel of each voxel (only voxels near a point are listed).
  std::unordered_map<int64_t, std::vector<int>> points_near;
  for (size_t p = 0; p < points.size(); ++p) {
    const Eigen::Vector3i centre = grid.VoxelOf(points[p].xyz);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3i voxel = centre + Eigen::Vector3i(dx, dy, dz);
          if (grid.Contains(voxel)) points_near[grid.Index(voxel)].push_back(static_cast<int>(p));
        }
      }
    }
  }
  // First pass: each component's surface voxels and the points beside it.
  struct Component {
    int64_t surface = 0;
    int64_t supported = 0;  // points claimed (each by the first component found beside it)
  };
  std::vector<Component> found;
  std::vector<uint8_t> claimed(points.size(), 0);
  ForEachSolidComponent(volume_, [&](const std::vector<int64_t>& voxels) {
    Component component;
    for (int64_t index : voxels) {
      component.surface += volume_.IsSurface(index);
      const auto near = points_near.find(index);
      if (near == points_near.end()) continue;
      for (int p : near->second) {
        if (claimed[p]) continue;
        claimed[p] = 1;
        ++component.supported;
      }
    }
    found.push_back(component);
  });
  int64_t supported = 0, supported_surface = 0, largest = 0;
  for (const Component& c : found) {
    largest = std::max(largest, c.surface);
    if (c.supported == 0) continue;
    supported += c.supported;
    supported_surface += c.surface;
  }
  std::vector<uint8_t> floater(found.size(), 0);
  int64_t removed = 0;
  double most_expected = 0.0;
  if (supported_surface > 0) {
    const double density = static_cast<double>(supported) / supported_surface;
    for (size_t k = 0; k < found.size(); ++k) {
      const Component& c = found[k];
      const double expected = density * c.surface;
      if (c.supported > 0 || expected < min_expected || 4 * c.surface >= largest) continue;
      floater[k] = 1;
      ++removed;
      most_expected = std::max(most_expected, expected);
    }
  }
  // Second pass (the same components in the same order): the floaters' voxels, then carved.
  std::vector<int64_t> carve;
  if (removed > 0) {
    size_t k = 0;
    ForEachSolidComponent(volume_, [&](const std::vector<int64_t>& voxels) {
      if (floater[k++]) carve.insert(carve.end(), voxels.begin(), voxels.end());
    });
  }
  for (int64_t voxel : carve) CarveAndQueue(voxel);
  if (components != nullptr) *components = removed;
  if (largest_expected != nullptr) *largest_expected = most_expected;
  return static_cast<int64_t>(carve.size());
}

}  // namespace raycarve
