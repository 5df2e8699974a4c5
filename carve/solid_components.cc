// IncrementalCarver's removal of solid components: specks, and floaters without sparse points.
#include "carve/incremental_carver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <sstream>
#include <utility>

#include <glog/logging.h>

#include "carve/free_space.h"
#include "carve/item_buffer_visibility.h"
#include "carve/layered_depth_visibility.h"
#include "carve/patch_correlation.h"
#include "carve/ray_image.h"


namespace raycarve {

namespace {

// The voxels of the 26-connected component of `volume`'s solid voxels that holds `start`, in
// breadth-first order from it; `seen` (a bit per voxel) marks them.
void ComponentVoxels(const Volume& volume, int64_t start, std::vector<uint64_t>* seen,
                     std::vector<int64_t>* component) {
  const VoxelGrid& grid = volume.grid();
  const Eigen::Vector3i& n = grid.dimensions();
  const auto mark = [seen](int64_t i) {
    const bool was = ((*seen)[i >> 6] >> (i & 63)) & 1;
    (*seen)[i >> 6] |= uint64_t{1} << (i & 63);
    return !was;
  };
  mark(start);
  component->assign(1, start);
  for (size_t k = 0; k < component->size(); ++k) {
    const Eigen::Vector3i voxel = grid.Voxel((*component)[k]);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3i next = voxel + Eigen::Vector3i(dx, dy, dz);
          if ((next.array() < 0).any() || (next.array() >= n.array()).any()) continue;
          const int64_t index = grid.Index(next);
          if (volume.IsSolid(index) && mark(index)) component->push_back(index);
        }
      }
    }
  }
}

// The 26-connected components of a volume's solid voxels, labelled from the runs of solid voxels
// along x (a run per row where a row crosses the solid) joined where runs of neighbouring rows
// touch: the work grows with the runs, not with the solid voxels (a fine grid's solid interior).
// Components are numbered in the order of their first voxel's index.
class SolidComponentLabels {
 public:
  explicit SolidComponentLabels(const Volume& volume) : grid_(volume.grid()) {
    const Eigen::Vector3i& n = grid_.dimensions();
    const int64_t rows = static_cast<int64_t>(n.y()) * n.z();
    row_runs_.assign(rows + 1, 0);
    const std::vector<uint64_t>& solid = volume.solid_bits();
    for (int64_t row = 0; row < rows; ++row) {
      row_runs_[row] = static_cast<int64_t>(run_x0_.size());
      const int64_t base = row * n.x();
      for (int64_t x = NextWith(solid, base, base + n.x(), true); x < base + n.x();) {
        const int64_t end = NextWith(solid, x, base + n.x(), false);
        run_x0_.push_back(static_cast<int32_t>(x - base));
        run_x1_.push_back(static_cast<int32_t>(end - 1 - base));
        x = NextWith(solid, end, base + n.x(), true);
      }
    }
    row_runs_[rows] = static_cast<int64_t>(run_x0_.size());
    // Runs of a row against those of the four rows before it among its eight neighbours.
    parent_.resize(run_x0_.size());
    std::iota(parent_.begin(), parent_.end(), 0);
    for (int z = 0; z < n.z(); ++z) {
      for (int y = 0; y < n.y(); ++y) {
        const int64_t row = static_cast<int64_t>(z) * n.y() + y;
        for (const auto& [dy, dz] : {std::pair{-1, 0}, {-1, -1}, {0, -1}, {1, -1}}) {
          if (y + dy < 0 || y + dy >= n.y() || z + dz < 0) continue;
          JoinRows(row, static_cast<int64_t>(z + dz) * n.y() + y + dy);
        }
      }
    }
    // Numbered by first run, which holds the component's first voxel.
    std::vector<int> number(run_x0_.size(), -1);
    run_component_.resize(run_x0_.size());
    for (int64_t row = 0; row < rows; ++row) {
      for (int64_t r = row_runs_[row]; r < row_runs_[row + 1]; ++r) {
        const int root = Find(static_cast<int>(r));
        if (number[root] < 0) {
          number[root] = static_cast<int>(first_voxel_.size());
          first_voxel_.push_back(row * n.x() + run_x0_[r]);
          size_.push_back(0);
          surface_.push_back(0);
        }
        const int c = number[root];
        run_component_[r] = c;
        size_[c] += run_x1_[r] - run_x0_[r] + 1;
        surface_[c] += CountSet(volume, row * n.x() + run_x0_[r], row * n.x() + run_x1_[r] + 1);
      }
    }
  }

  int count() const { return static_cast<int>(first_voxel_.size()); }
  int64_t first_voxel(int c) const { return first_voxel_[c]; }
  int64_t size(int c) const { return size_[c]; }
  int64_t surface(int c) const { return surface_[c]; }

  // The component of a voxel; -1 where it is not solid.
  int ComponentOf(const Eigen::Vector3i& voxel) const {
    const int64_t row = static_cast<int64_t>(voxel.z()) * grid_.dimensions().y() + voxel.y();
    const auto begin = run_x1_.begin() + row_runs_[row], end = run_x1_.begin() + row_runs_[row + 1];
    const auto run = std::lower_bound(begin, end, voxel.x());  // the first ending at or after x
    if (run == end || run_x0_[run - run_x1_.begin()] > voxel.x()) return -1;
    return run_component_[run - run_x1_.begin()];
  }

 private:
  // The first index in [from, to) whose bit is `set`, or `to`.
  static int64_t NextWith(const std::vector<uint64_t>& bits, int64_t from, int64_t to, bool set) {
    while (from < to) {
      uint64_t word = bits[from >> 6];
      if (!set) word = ~word;
      word >>= (from & 63);
      if (word != 0) return std::min(to, from + __builtin_ctzll(word));
      from = (from | 63) + 1;
    }
    return to;
  }

  // The surface voxels in [from, to).
  static int64_t CountSet(const Volume& volume, int64_t from, int64_t to) {
    const std::vector<uint64_t>& bits = volume.surface_bits();
    int64_t count = 0;
    while (from < to) {
      const int64_t word_end = std::min(to, (from | 63) + 1);
      uint64_t word = bits[from >> 6] >> (from & 63);
      const int64_t width = word_end - from;
      if (width < 64) word &= (uint64_t{1} << width) - 1;
      count += __builtin_popcountll(word);
      from = word_end;
    }
    return count;
  }

  int Find(int run) {
    int root = run;
    while (parent_[root] != root) root = parent_[root];
    while (parent_[run] != root) {
      const int next = parent_[run];
      parent_[run] = root;
      run = next;
    }
    return root;
  }

  void Union(int a, int b) {
    a = Find(a);
    b = Find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

  // Joins the runs of two rows that touch, diagonals included (x ranges within one voxel).
  void JoinRows(int64_t row, int64_t other) {
    int64_t i = row_runs_[row], j = row_runs_[other];
    while (i < row_runs_[row + 1] && j < row_runs_[other + 1]) {
      if (run_x0_[i] <= run_x1_[j] + 1 && run_x0_[j] <= run_x1_[i] + 1) {
        Union(static_cast<int>(i), static_cast<int>(j));
      }
      if (run_x1_[i] < run_x1_[j]) {
        ++i;
      } else {
        ++j;
      }
    }
  }

  const VoxelGrid& grid_;
  std::vector<int64_t> row_runs_;  // row (y + ny z): its runs are [row_runs_[row], [row + 1])
  std::vector<int32_t> run_x0_, run_x1_;  // a run's first and last x
  std::vector<int> parent_;               // union-find over runs
  std::vector<int> run_component_;
  std::vector<int64_t> first_voxel_, size_, surface_;
};

}  // namespace

int64_t IncrementalCarver::RemoveSmallComponents(int64_t min_voxels) {
  const SolidComponentLabels labels(volume_);
  std::vector<uint64_t> seen((volume_.grid().num_voxels() + 63) / 64, 0);
  std::vector<int64_t> small, component;
  for (int c = 0; c < labels.count(); ++c) {
    if (labels.size(c) >= min_voxels) continue;
    ComponentVoxels(volume_, labels.first_voxel(c), &seen, &component);
    small.insert(small.end(), component.begin(), component.end());
  }
  for (int64_t voxel : small) CarveAndQueue(voxel);
  return static_cast<int64_t>(small.size());
}

int64_t IncrementalCarver::RemoveUnsupportedComponents(const std::vector<SurfacePoint>& points,
                                                       double min_expected,
                                                       int64_t* components,
                                                       double* largest_expected) {
  const VoxelGrid& grid = volume_.grid();
  const SolidComponentLabels labels(volume_);
  // Each point is claimed by the first component (in the labels' order) with a voxel in or
  // beside the point's voxel.
  std::vector<int64_t> supported(labels.count(), 0);
  for (const SurfacePoint& point : points) {
    const Eigen::Vector3i centre = grid.VoxelOf(point.xyz);
    int first = -1;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3i voxel = centre + Eigen::Vector3i(dx, dy, dz);
          if (!grid.Contains(voxel)) continue;
          const int c = labels.ComponentOf(voxel);
          if (c >= 0 && (first < 0 || c < first)) first = c;
        }
      }
    }
    if (first >= 0) ++supported[first];
  }
  int64_t supported_points = 0, supported_surface = 0, largest = 0;
  for (int c = 0; c < labels.count(); ++c) {
    largest = std::max(largest, labels.surface(c));
    if (supported[c] == 0) continue;
    supported_points += supported[c];
    supported_surface += labels.surface(c);
  }
  int64_t removed = 0;
  double most_expected = 0.0;
  std::vector<int64_t> carve, component;
  if (supported_surface > 0) {
    const double density = static_cast<double>(supported_points) / supported_surface;
    std::vector<uint64_t> seen((grid.num_voxels() + 63) / 64, 0);
    for (int c = 0; c < labels.count(); ++c) {
      const double expected = density * labels.surface(c);
      if (supported[c] > 0 || expected < min_expected || 4 * labels.surface(c) >= largest) {
        continue;
      }
      ++removed;
      most_expected = std::max(most_expected, expected);
      ComponentVoxels(volume_, labels.first_voxel(c), &seen, &component);
      carve.insert(carve.end(), component.begin(), component.end());
    }
  }
  for (int64_t voxel : carve) CarveAndQueue(voxel);
  if (components != nullptr) *components = removed;
  if (largest_expected != nullptr) *largest_expected = most_expected;
  return static_cast<int64_t>(carve.size());
}

}  // namespace raycarve
