// Levelling onto the supporting plane, on boxes whose answer is known: a thin slab near the plane
// (a mat), one farther off, one beyond the plane's sparse points, and a tall block.
#include "export/support_levelling.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "export/surface_mesh.h"
#include "tests/ground_fixture.h"

namespace raycarve {
namespace exporter {
namespace {

constexpr double kVoxel = 0.05;

// A closed box (8 corners, 12 triangles wound outwards), with the area-weighted corner normals.
TriangleMesh Box(const Eigen::Vector3f& low, const Eigen::Vector3f& high) {
  TriangleMesh mesh;
  for (int k = 0; k < 8; ++k) {
    mesh.vertices.emplace_back(k & 1 ? high.x() : low.x(), k & 2 ? high.y() : low.y(),
                               k & 4 ? high.z() : low.z());
  }
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) {
    mesh.triangles.emplace_back(f[0], f[1], f[2]);
    mesh.triangles.emplace_back(f[0], f[2], f[3]);
  }
  ComputeVertexNormals(&mesh);
  return mesh;
}

// The plane z = 0, its sparse points over [-1, 1]^2.
Ground PlaneZ0() {
  return testing::GridGround(/*axis=*/2, /*half=*/1.0, /*spacing=*/0.25, /*depth=*/0.01,
                             /*radius=*/0.3, /*outline=*/true);
}

TEST(LevelOntoSupport, AThinTopNearThePlaneLiesOnItWithItsUndersideBelow) {
  // Top 0.8 voxels above the plane, underside 0.4 above: a mat the carve left a voxel thick.
  TriangleMesh mesh = Box({-0.5f, -0.5f, 0.02f}, {0.5f, 0.5f, 0.04f});
  ASSERT_EQ(mesh.normals[0].z() < -0.5f, true);  // the underside's corners face down
  const SupportLevelling levelling = LevelOntoSupport(PlaneZ0(), kVoxel, 0.0, &mesh);
  EXPECT_EQ(levelling.vertices, 8);
  for (int k = 0; k < 8; ++k) {
    EXPECT_NEAR(mesh.vertices[k].z(), k & 4 ? 0.0 : -0.5 * kVoxel, 1e-6) << k;
    EXPECT_FLOAT_EQ(mesh.vertices[k].x(), k & 1 ? 0.5f : -0.5f);  // along the plane: unmoved
  }
  EXPECT_NEAR(levelling.mean_move, (4 * 0.04 + 4 * (0.02 + 0.025)) / 8, 1e-6);
  EXPECT_GT(mesh.normals[4].z(), 0.5f);  // recomputed
}

TEST(LevelOntoSupport, PartWayBetweenOneAndTwoVoxelsNoneBeyond) {
  // A top 1.5 voxels up goes half the way, to 0.75 voxels; its underside at 1.2 voxels is
  // already above the top's target and faces down: it goes 0.8 of the way to half a voxel under.
  TriangleMesh mesh = Box({-0.5f, -0.5f, 0.06f}, {0.5f, 0.5f, 0.075f});
  LevelOntoSupport(PlaneZ0(), kVoxel, 0.0, &mesh);
  EXPECT_NEAR(mesh.vertices[4].z(), 0.75 * kVoxel, 1e-6);
  EXPECT_NEAR(mesh.vertices[0].z(), 0.06 + 0.8 * (-0.025 - 0.06), 1e-6);

  TriangleMesh far = Box({-0.5f, -0.5f, 0.2f}, {0.5f, 0.5f, 0.3f});
  const TriangleMesh original = far;
  EXPECT_EQ(LevelOntoSupport(PlaneZ0(), kVoxel, 0.0, &far).vertices, 0);
  EXPECT_EQ(far.vertices, original.vertices);
}

TEST(LevelOntoSupport, OnAFineGridTheBandIsTheOneAskedFor) {
  // Voxels of 0.002 with a band of 0.01 asked for (two voxels of a grid five times coarser): the
  // band is 0.01, not two voxels (0.004). A slab from 0.001 to 0.004 (a bulge of two fine voxels)
  // goes onto the plane, its underside half a voxel under it; a top at 0.0075 goes half the way;
  // one at 0.012 stays.
  constexpr double kFine = 0.002, kBand = 0.01;
  TriangleMesh bulge = Box({-0.5f, -0.5f, 0.001f}, {0.5f, 0.5f, 0.004f});
  const SupportLevelling levelling = LevelOntoSupport(PlaneZ0(), kFine, kBand, &bulge);
  EXPECT_DOUBLE_EQ(levelling.band, kBand);
  EXPECT_EQ(levelling.vertices, 8);
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(bulge.vertices[k].z(), k & 4 ? 0.0 : -0.5 * kFine, 1e-6) << k;

  TriangleMesh higher = Box({-0.5f, -0.5f, 0.0065f}, {0.5f, 0.5f, 0.0075f});
  LevelOntoSupport(PlaneZ0(), kFine, kBand, &higher);
  EXPECT_NEAR(higher.vertices[4].z(), 0.5 * 0.0075, 1e-6);

  TriangleMesh above = Box({-0.5f, -0.5f, 0.011f}, {0.5f, 0.5f, 0.012f});
  EXPECT_EQ(LevelOntoSupport(PlaneZ0(), kFine, kBand, &above).vertices, 0);
  // Without it, two fine voxels: the slab at 0.0075 stays where it is.
  TriangleMesh narrow = Box({-0.5f, -0.5f, 0.0065f}, {0.5f, 0.5f, 0.0075f});
  EXPECT_DOUBLE_EQ(LevelOntoSupport(PlaneZ0(), kFine, 0.0, &narrow).band, 2.0 * kFine);
  EXPECT_FLOAT_EQ(narrow.vertices[4].z(), 0.0075f);
  // A band asked for that is narrower than two voxels changes nothing.
  EXPECT_DOUBLE_EQ(LevelOntoSupport(PlaneZ0(), kVoxel, kBand, &narrow).band, 2.0 * kVoxel);
}

TEST(LevelOntoSupport, ASidewaysFacingVertexNearThePlaneGoesOntoItAsTheTopDoes) {
  // A fin standing across the plane's band: its long sides outweigh its ends and its top, so
  // every corner faces sideways. Its foot (0.2 voxels up) goes onto the plane, its top (1.2
  // voxels up) 0.8 of the way: nothing near the plane is left standing as a spike.
  TriangleMesh mesh = Box({-0.5f, -0.005f, 0.01f}, {0.5f, 0.005f, 0.06f});
  for (int k = 0; k < 8; ++k) ASSERT_LT(std::abs(mesh.normals[k].z()), 0.5f) << k;
  EXPECT_EQ(LevelOntoSupport(PlaneZ0(), kVoxel, 0.0, &mesh).vertices, 8);
  for (int k = 0; k < 8; ++k) {
    EXPECT_NEAR(mesh.vertices[k].z(), k & 4 ? 0.06 * 0.2 : 0.0, 1e-6) << k;
  }
}

TEST(LevelOntoSupport, OnlyWhereThePlanesPointsAre) {
  // The same mat beyond the footprint's reach (x from 2 to 3): no point shows the plane there.
  TriangleMesh mesh = Box({2.0f, -0.5f, 0.02f}, {3.0f, 0.5f, 0.04f});
  const TriangleMesh original = mesh;
  EXPECT_EQ(LevelOntoSupport(PlaneZ0(), kVoxel, 0.0, &mesh).vertices, 0);
  EXPECT_EQ(mesh.vertices, original.vertices);
  // And nothing without a support.
  EXPECT_EQ(LevelOntoSupport(Ground(), kVoxel, 0.0, &mesh).vertices, 0);
}

TEST(LevelOntoSupport, ABlockStandingOnThePlaneKeepsItsTopAndWalls) {
  // A block from the plane up to 1: its top is far above and stays; its bottom corners, on the
  // plane already, face sideways (the walls' area outweighs the base's) or down, and stay on it
  // or go at most half a voxel under it; nothing moves along the plane.
  TriangleMesh mesh = Box({-0.2f, -0.2f, 0.0f}, {0.2f, 0.2f, 1.0f});
  const TriangleMesh original = mesh;
  LevelOntoSupport(PlaneZ0(), kVoxel, 0.0, &mesh);
  for (int k = 0; k < 8; ++k) {
    EXPECT_EQ(mesh.vertices[k].head<2>(), original.vertices[k].head<2>()) << k;
    if (k & 4) {
      EXPECT_FLOAT_EQ(mesh.vertices[k].z(), 1.0f) << k;
    } else {
      EXPECT_LE(mesh.vertices[k].z(), 0.0f) << k;
      EXPECT_GE(mesh.vertices[k].z(), -0.5 * kVoxel - 1e-6) << k;
    }
  }
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
