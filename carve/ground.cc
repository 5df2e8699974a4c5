#include "carve/ground.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <glog/logging.h>

namespace raycarve {
namespace {

constexpr double kMaxCells = 4096;

}  // namespace

GroundMap::GroundMap(const Ground& ground) {
  CHECK(!ground.empty() && ground.normal.norm() > 0.0);
  normal_ = ground.normal.normalized();
  offset_ = ground.offset / ground.normal.norm();
  const Eigen::Vector3d helper =
      std::abs(normal_.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  u_ = normal_.cross(helper).normalized();
  v_ = normal_.cross(u_);
  Eigen::Vector2d low(HUGE_VAL, HUGE_VAL), high(-HUGE_VAL, -HUGE_VAL);
  for (const auto* points : {&ground.footprint, &ground.holes}) {
    for (const Eigen::Vector3d& point : *points) {
      const Eigen::Vector2d q = OnPlane(point);
      low = low.cwiseMin(q);
      high = high.cwiseMax(q);
    }
  }
  low_ = low.array() - ground.radius;
  const Eigen::Vector2d extent = (high - low).array() + 2.0 * ground.radius;
  cell_ = std::max(ground.radius / 4.0, extent.maxCoeff() / (kMaxCells - 2));
  cols_ = static_cast<int>(std::ceil(extent.x() / cell_)) + 1;
  rows_ = static_cast<int>(std::ceil(extent.y() / cell_)) + 1;
  cells_.assign(static_cast<size_t>(cols_) * rows_, Foot::kNeither);
  MarkDiscs(ground.footprint, ground.radius, Foot::kGround);
  // Past the outline's edges by one spacing of its points (the reach is two): about where the
  // next point would have been, where the ground's edge lies beyond its outermost points.
  MarkOutline(ground.outline, 0.5 * ground.radius);
  MarkDiscs(ground.holes, ground.radius, Foot::kNearHole);
}

int GroundMap::Col(const Eigen::Vector2d& q) const {
  return static_cast<int>(std::floor(std::clamp((q.x() - low_.x()) / cell_, -1.0, cols_ + 1.0)));
}

int GroundMap::Row(const Eigen::Vector2d& q) const {
  return static_cast<int>(std::floor(std::clamp((q.y() - low_.y()) / cell_, -1.0, rows_ + 1.0)));
}

void GroundMap::MarkDiscs(const std::vector<Eigen::Vector3d>& points, double radius, Foot value) {
  const int reach = static_cast<int>(std::ceil(radius / cell_));
  for (const Eigen::Vector3d& point : points) {
    const Eigen::Vector2d q = OnPlane(point);
    const int col = Col(q), row = Row(q);
    for (int r = std::max(0, row - reach); r <= std::min(rows_ - 1, row + reach); ++r) {
      for (int c = std::max(0, col - reach); c <= std::min(cols_ - 1, col + reach); ++c) {
        if ((CellCentre(c, r) - q).squaredNorm() <= radius * radius) {
          cells_[static_cast<size_t>(r) * cols_ + c] = value;
        }
      }
    }
  }
}

void GroundMap::MarkOutline(const std::vector<Eigen::Vector3d>& outline, double radius) {
  if (outline.size() < 3) return;
  std::vector<Eigen::Vector2d> corners;
  for (const Eigen::Vector3d& point : outline) corners.push_back(OnPlane(point));
  const size_t n = corners.size();
  // Within `radius` of each edge: the ground runs on past its outermost points.
  const int reach = static_cast<int>(std::ceil(radius / cell_));
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = corners[i];
    const Eigen::Vector2d& b = corners[(i + 1) % n];
    const Eigen::Vector2d ab = b - a;
    const double length2 = ab.squaredNorm();
    const int c0 = std::max(0, std::min(Col(a), Col(b)) - reach);
    const int c1 = std::min(cols_ - 1, std::max(Col(a), Col(b)) + reach);
    const int r0 = std::max(0, std::min(Row(a), Row(b)) - reach);
    const int r1 = std::min(rows_ - 1, std::max(Row(a), Row(b)) + reach);
    for (int r = r0; r <= r1; ++r) {
      for (int c = c0; c <= c1; ++c) {
        const Eigen::Vector2d q = CellCentre(c, r);
        const double t = length2 > 0.0 ? std::clamp((q - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
        if ((a + t * ab - q).squaredNorm() <= radius * radius) {
          cells_[static_cast<size_t>(r) * cols_ + c] = Foot::kGround;
        }
      }
    }
  }
  // Row by row: a convex polygon meets the line through the row's cell centres in one interval,
  // between the lowest and highest crossing of its edges.
  for (int r = 0; r < rows_; ++r) {
    const double y = CellCentre(0, r).y();
    double low = HUGE_VAL, high = -HUGE_VAL;
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d& a = corners[i];
      const Eigen::Vector2d& b = corners[(i + 1) % n];
      if ((a.y() > y) == (b.y() > y)) continue;  // the edge does not cross the line
      const double x = a.x() + (y - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
      low = std::min(low, x);
      high = std::max(high, x);
    }
    if (!(low <= high)) continue;
    const int first = std::max(0, static_cast<int>(std::ceil((low - low_.x()) / cell_ - 0.5)));
    const int last = std::min(cols_ - 1, static_cast<int>(std::floor((high - low_.x()) / cell_ - 0.5)));
    for (int c = first; c <= last; ++c) cells_[static_cast<size_t>(r) * cols_ + c] = Foot::kGround;
  }
}

GroundMap::Foot GroundMap::At(const Eigen::Vector3d& point) const {
  const Eigen::Vector2d q = OnPlane(point);
  const int col = Col(q), row = Row(q);
  if (col < 0 || row < 0 || col >= cols_ || row >= rows_) return Foot::kNeither;
  return cells_[static_cast<size_t>(row) * cols_ + col];
}

bool GroundMap::NearGround(const Eigen::Vector3d& point, double reach) const {
  const Eigen::Vector2d q = OnPlane(point);
  const int col = Col(q), row = Row(q);
  const int cells = static_cast<int>(std::ceil(reach / cell_));
  for (int r = std::max(0, row - cells); r <= std::min(rows_ - 1, row + cells); ++r) {
    for (int c = std::max(0, col - cells); c <= std::min(cols_ - 1, col + cells); ++c) {
      if (cells_[static_cast<size_t>(r) * cols_ + c] == Foot::kGround &&
          (CellCentre(c, r) - q).norm() <= reach + cell_) {
        return true;
      }
    }
  }
  return false;
}

BelowGround SplitBelowGround(const VoxelGrid& grid, const Ground& ground) {
  BelowGround split;
  if (ground.empty() || !(ground.normal.norm() > 0.0)) return split;
  const GroundMap map(ground);
  const double below = ground.depth + grid.voxel_size();
  const Eigen::Vector3i& dims = grid.dimensions();
  for (int z = 0; z < dims.z(); ++z) {
    for (int y = 0; y < dims.y(); ++y) {
      for (int x = 0; x < dims.x(); ++x) {
        const Eigen::Vector3i voxel(x, y, z);
        const Eigen::Vector3d centre = grid.Centre(voxel);
        if (!(map.Height(centre) < -below)) continue;
        const GroundMap::Foot foot = map.At(centre);
        if (foot == GroundMap::Foot::kGround) split.held.push_back(grid.Index(voxel));
        if (foot == GroundMap::Foot::kNeither) split.beyond.push_back(grid.Index(voxel));
      }
    }
  }
  return split;
}

std::vector<int64_t> GroundVoxels(const VoxelGrid& grid, const Ground& ground) {
  return SplitBelowGround(grid, ground).held;
}

std::vector<int64_t> BeyondGroundVoxels(const VoxelGrid& grid, const Ground& ground) {
  return SplitBelowGround(grid, ground).beyond;
}

}  // namespace raycarve
