// The per-vertex marks of what the smooth mesh leaves out (export/mesh_exclusions.h): the held
// ground's fill, beyond the photos' frames, unseen, and the unseen kept near the seen.
#include "export/mesh_exclusions.h"

#include <algorithm>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "carve/volume.h"
#include "tests/test_support.h"

namespace raycarve {
namespace exporter {
namespace {

TEST(MeshExclusions, TheHeldGroundsSidesAndUndersideAreFillAndItsTopIsNot) {
  // The ground the carve held: a slab under the plane z = 0.5 over the square [0.25, 0.75]^2,
  // away from the grid's walls. Its top is the floor the photos saw; its sides and underside
  // stand for nothing they saw.
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()), 24);
  const double voxel = grid.voxel_size();
  std::vector<uint64_t> solid((grid.num_voxels() + 63) / 64, 0);
  for (int k = 0; k < 12; ++k) {
    for (int j = 6; j < 18; ++j) {
      for (int i = 6; i < 18; ++i) {
        const int64_t index = grid.Index(Eigen::Vector3i(i, j, k));
        solid[index >> 6] |= uint64_t{1} << (index & 63);
      }
    }
  }
  Ground ground;
  ground.normal = Eigen::Vector3d::UnitZ();
  ground.offset = -0.5;
  ground.depth = 0.01;
  ground.radius = 2.0 * voxel;
  for (int j = 0; j <= 12; ++j) {
    for (int i = 0; i <= 12; ++i) ground.footprint.emplace_back(0.25 + i * voxel, 0.25 + j * voxel, 0.5);
  }
  ground.outline = {{0.25, 0.25, 0.5}, {0.75, 0.25, 0.5}, {0.75, 0.75, 0.5}, {0.25, 0.75, 0.5}};
  SurfaceMeshSummary summary;
  const TriangleMesh mesh = MeshSolidVoxels(Volume(grid, solid), SurfaceMeshOptions(), &summary);
  ASSERT_FALSE(mesh.empty());
  const std::vector<uint8_t> fill = GroundFillVertices(mesh, ground, voxel);
  ASSERT_EQ(fill.size(), mesh.vertices.size());
  int tops = 0, sides = 0, bottoms = 0;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3f& p = mesh.vertices[i];
    const Eigen::Vector3f& n = mesh.normals[i];
    const bool inner = (p.head<2>().array() > 0.25f + 2 * voxel).all() &&
                       (p.head<2>().array() < 0.75f - 2 * voxel).all();
    if (p.z() > 0.5 - 0.25 * voxel && inner) {
      ++tops;
      EXPECT_EQ(fill[i], 0) << p.transpose() << " normal " << n.transpose();
    } else if (p.z() < 0.5 - 2 * voxel && p.z() > 2 * voxel) {
      ++sides;
      EXPECT_EQ(fill[i], 1) << p.transpose() << " normal " << n.transpose();
    } else if (p.z() < 0.25 * voxel && inner) {
      ++bottoms;
      EXPECT_EQ(fill[i], 1) << p.transpose();
    }
  }
  EXPECT_GT(tops, 50);
  EXPECT_GT(sides, 50);
  EXPECT_GT(bottoms, 50);
  // No ground: no fill.
  const std::vector<uint8_t> none = GroundFillVertices(mesh, Ground(), voxel);
  EXPECT_EQ(std::count(none.begin(), none.end(), uint8_t{1}), 0);
}


TEST(MeshExclusions, VerticesBeyondTheFramesOfAllButOnePhotoAreUncovered) {
  // Two photos facing each other across the origin, 100 px square with a focal length of 100 px:
  // each frame holds what lies within half its depth of its axis.
  std::vector<CalibratedView> views = {
      testing::PinholeViewLookingAtOrigin(Eigen::Vector3d(0, 0, 5), 100, 100, 100.0),
      testing::PinholeViewLookingAtOrigin(Eigen::Vector3d(0, 0, -5), 100, 100, 100.0)};
  TriangleMesh mesh;
  mesh.vertices = {
      {0.0f, 0.0f, 0.0f},   // in both frames
      {2.0f, 0.0f, 0.0f},   // in both, near their edges
      {3.0f, 0.0f, 0.0f},   // beside both
      {2.2f, 0.0f, 2.0f},   // beside the near photo's frame, in the far one's
      {0.0f, 0.0f, 6.0f}};  // behind the near photo, in the far one's frame
  EXPECT_EQ(UncoveredVertices(mesh, views, 2), (std::vector<uint8_t>{0, 0, 1, 1, 1}));
  EXPECT_EQ(UncoveredVertices(mesh, views, 1), (std::vector<uint8_t>{0, 0, 1, 0, 0}));
  // A pixel beyond the distorted frame (`valid` 0) holds nothing of the photo.
  views[1].valid.setTo(0);
  EXPECT_EQ(UncoveredVertices(mesh, views, 1), (std::vector<uint8_t>{0, 0, 1, 1, 1}));
}

TEST(MeshExclusions, VerticesBehindAnOccluderFromEveryPhotoAreUnseen) {
  // Three photos side by side at z = 5 looking at the origin, a square of 2 x 2 at z = 0 between
  // them and what lies behind it; 100 px square, focal length 100 px.
  std::vector<CalibratedView> views;
  for (double x : {-1.0, 0.0, 1.0}) {
    views.push_back(testing::PinholeViewLookingAtOrigin(Eigen::Vector3d(x, 0, 5), 100, 100, 100.0));
  }
  TriangleMesh mesh;
  mesh.vertices = {{-1.0f, -1.0f, 0.0f}, {1.0f, -1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {-1.0f, 1.0f, 0.0f},
                   {0.0f, 0.0f, 0.5f},    // in front of the square: every photo sees it
                   {0.0f, 0.0f, -0.5f},   // behind its middle: none does
                   {1.05f, 0.0f, -1.0f},  // behind its edge: the photo at x = 1 sees past the edge
                   {0.0f, 0.0f, 0.02f}};  // on the square's near side within the tolerance
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  EXPECT_EQ(UnseenVertices(mesh, views, 2, 0.05), (std::vector<uint8_t>{0, 0, 0, 0, 0, 1, 1, 0}));
  EXPECT_EQ(UnseenVertices(mesh, views, 1, 0.05), (std::vector<uint8_t>{0, 0, 0, 0, 0, 1, 0, 0}));
  // A vertex just behind the surface, within the tolerance, counts as on it.
  mesh.vertices[7].z() = -0.02f;
  EXPECT_EQ(UnseenVertices(mesh, views, 2, 0.05)[7], 0);
  EXPECT_EQ(UnseenVertices(mesh, views, 2, 0.01)[7], 1);
  // A pixel beyond the distorted frame (`valid` 0) sees nothing.
  views[2].valid.setTo(0);
  EXPECT_EQ(UnseenVertices(mesh, views, 1, 0.05)[6], 1);
}

TEST(MeshExclusions, UnseenVerticesWithinReachOfTheSeenSurfaceAlongTheMeshStay) {
  // A strip of triangles along x: vertices at x = 0, 0.4, 0.8, ... 2.4 on two rows (y 0 and 0.1).
  // Seen: x = 0; unseen: the rest; the wall (excluded): x = 2.4. Reach 1.0 along the edges: the
  // unseen vertices at x 0.4 and 0.8 stay marked no more (the row's edges reach them), those from
  // 1.2 on keep their mark; the wall, although seen, is no start.
  TriangleMesh mesh;
  constexpr int kColumns = 7;
  for (int c = 0; c < kColumns; ++c) {
    mesh.vertices.emplace_back(0.4f * c, 0.0f, 0.0f);
    mesh.vertices.emplace_back(0.4f * c, 0.1f, 0.0f);
  }
  for (int c = 0; c + 1 < kColumns; ++c) {
    const int a = 2 * c, b = 2 * c + 1, d = 2 * c + 2, e = 2 * c + 3;
    mesh.triangles.emplace_back(a, d, e);
    mesh.triangles.emplace_back(a, e, b);
  }
  std::vector<uint8_t> unseen(mesh.vertices.size(), 1), excluded(mesh.vertices.size(), 0);
  unseen[0] = unseen[1] = 0;
  excluded[12] = excluded[13] = 1;
  unseen[12] = unseen[13] = 0;  // seen, but on the wall
  std::vector<uint8_t> marks = unseen;
  EXPECT_EQ(KeepUnseenNearSeen(mesh, excluded, 1.0, &marks), 4);
  EXPECT_EQ(marks, (std::vector<uint8_t>{0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 0, 0}));
  // A reach of nothing keeps the marks as they were.
  marks = unseen;
  EXPECT_EQ(KeepUnseenNearSeen(mesh, excluded, 0.0, &marks), 0);
  EXPECT_EQ(marks, unseen);
  // Without a seen start nothing is cleared (the wall does not count).
  std::vector<uint8_t> none(mesh.vertices.size(), 1);
  none[12] = none[13] = 0;
  EXPECT_EQ(KeepUnseenNearSeen(mesh, excluded, 10.0, &none), 0);
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
