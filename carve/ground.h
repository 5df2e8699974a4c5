#pragma once
// The ground under an unmasked capture's subject: what lies below a supporting plane (a table, a
// floor) that the sparse points show from above is solid that no photo sees. Colour carving that
// runs through a plain or repetitive floor would open it and show the photos the volume under it;
// voxels under the ground are kept instead, and space below the plane past the ground's edge,
// where no sparse point shows a surface, is empty (the photos look down past the edge there).

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "carve/voxel_grid.h"

namespace raycarve {

struct Ground {
  // The plane normal . x + offset = 0, normal a unit vector towards the cameras.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double offset = 0.0;
  // A point more than `depth` below the plane is under it (the plane's tolerance).
  double depth = 0.0;
  // Where the plane is ground: inside this convex outline on the plane (the hull of the sparse
  // points on it) or within half `radius` of it (one spacing of its points: about where the next
  // point past the outermost would be), or within `radius` of one of the footprint points (those
  // points), and not within `radius` of a hole (the foot on the plane of a point seen below it: a
  // step down, the floor beyond a table's edge). Empty footprint: no ground.
  std::vector<Eigen::Vector3d> footprint;
  std::vector<Eigen::Vector3d> outline;  // in order around the hull; may be empty
  std::vector<Eigen::Vector3d> holes;
  double radius = 0.0;
  // Points on the plane left out of the footprint: lone, unchecked (exporter::GroundUnder).
  int lone_points = 0;

  bool empty() const { return footprint.empty() || !(radius > 0.0); }
  // Signed distance of `point` from the plane (positive on the cameras' side).
  double Height(const Eigen::Vector3d& point) const { return normal.dot(point) + offset; }
};

// The ground as a raster over its plane (cells of a quarter of its radius, or coarser where that
// would exceed 4096 a side).
class GroundMap {
 public:
  explicit GroundMap(const Ground& ground);  // ground must not be empty (CHECKed)

  // Signed distance of `point` from the plane (positive on the cameras' side).
  double Height(const Eigen::Vector3d& point) const { return normal_.dot(point) + offset_; }
  // Where the foot of `point` on the plane falls: on the ground, near a hole, or neither.
  enum class Foot : uint8_t { kNeither = 0, kGround = 1, kNearHole = 2 };
  Foot At(const Eigen::Vector3d& point) const;
  // Whether a ground cell lies within `reach` (along the plane) of the foot of `point`.
  bool NearGround(const Eigen::Vector3d& point, double reach) const;

 private:
  Eigen::Vector2d OnPlane(const Eigen::Vector3d& point) const {
    return Eigen::Vector2d(u_.dot(point), v_.dot(point));
  }
  Eigen::Vector2d CellCentre(int col, int row) const {
    return low_ + cell_ * Eigen::Vector2d(col + 0.5, row + 0.5);
  }
  int Col(const Eigen::Vector2d& q) const;
  int Row(const Eigen::Vector2d& q) const;
  void MarkDiscs(const std::vector<Eigen::Vector3d>& points, double radius, Foot value);
  void MarkOutline(const std::vector<Eigen::Vector3d>& outline, double radius);

  Eigen::Vector3d normal_, u_, v_;
  double offset_ = 0.0;
  Eigen::Vector2d low_;
  double cell_ = 1.0;
  int cols_ = 0, rows_ = 0;
  std::vector<Foot> cells_;
};

// The voxels of `grid` more than the ground's depth and a voxel below the plane (by their
// centres), in index order: `held`, whose foot is on the ground (GroundVoxels), and `beyond`,
// whose foot is neither on it nor near a hole (BeyondGroundVoxels). One pass over the grid.
struct BelowGround {
  std::vector<int64_t> held;
  std::vector<int64_t> beyond;
};
BelowGround SplitBelowGround(const VoxelGrid& grid, const Ground& ground);

// The voxels of `grid` under the ground (centre more than the ground's depth and a voxel below
// the plane, foot on the ground), in index order; none for an empty ground.
std::vector<int64_t> GroundVoxels(const VoxelGrid& grid, const Ground& ground);

// The voxels of `grid` as far below the plane but off the ground and beyond `radius` of every
// hole, in index order: past the ground's edge the photos look down beyond it (at a backdrop, the
// sky), and no sparse point says that a surface is there. Empty space, carved before colouring.
std::vector<int64_t> BeyondGroundVoxels(const VoxelGrid& grid, const Ground& ground);

}  // namespace raycarve
