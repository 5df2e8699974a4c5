#include "carve/free_space.h"

#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "tests/test_support.h"

namespace raycarve {
namespace {

// Whether the segment from `a` to `b` meets the closed cube of `voxel`, grown by `slack`.
bool SegmentMeetsVoxel(const VoxelGrid& grid, const Eigen::Vector3i& voxel,
                       const Eigen::Vector3d& a, const Eigen::Vector3d& b, double slack) {
  const Eigen::Vector3d low = grid.Corner(voxel, 0) - Eigen::Vector3d::Constant(slack);
  const Eigen::Vector3d high = grid.Corner(voxel, 7) + Eigen::Vector3d::Constant(slack);
  const double length = (b - a).norm();
  double t_near = 0.0, t_far = 0.0;
  if (!ClipRayToBox(a, (b - a) / length, Eigen::AlignedBox3d(low, high), &t_near, &t_far)) return false;
  return t_far >= 0.0 && t_near <= length;
}

TEST(SegmentVoxels, ListsEveryVoxelTheSegmentPassesThroughAndNoOther) {
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d(-1, -0.5, -0.7), Eigen::Vector3d(1, 0.5, 0.7)), 40);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-2.0, 2.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d a(uniform(random), uniform(random), uniform(random));
    const Eigen::Vector3d b(uniform(random), uniform(random), uniform(random));
    std::vector<int64_t> listed;
    SegmentVoxels(grid, a, b, &listed);
    const std::set<int64_t> unique(listed.begin(), listed.end());
    EXPECT_EQ(unique.size(), listed.size()) << "a voxel listed twice";
    // Every voxel listed meets the segment; consecutive ones share a face.
    for (size_t i = 0; i < listed.size(); ++i) {
      const Eigen::Vector3i voxel = grid.Voxel(listed[i]);
      EXPECT_TRUE(SegmentMeetsVoxel(grid, voxel, a, b, 1e-9 * grid.voxel_size()));
      if (i > 0) {
        EXPECT_EQ((voxel - grid.Voxel(listed[i - 1])).cwiseAbs().sum(), 1);
      }
    }
    // Every point sampled along the segment inside the grid lies in a listed voxel.
    for (int s = 0; s <= 2000; ++s) {
      const Eigen::Vector3d point = a + (s / 2000.0) * (b - a);
      const Eigen::Vector3i voxel = grid.VoxelOf(point);
      if (!grid.Contains(voxel)) continue;
      // Points within a hair of a face may round into the neighbour: skip those.
      const Eigen::Vector3d local = (point - grid.origin()) / grid.voxel_size();
      const Eigen::Vector3d fraction = local - local.array().floor().matrix();
      if ((fraction.array() < 1e-6).any() || (fraction.array() > 1 - 1e-6).any()) continue;
      EXPECT_TRUE(unique.count(grid.Index(voxel))) << "trial " << trial << " sample " << s;
    }
  }
}

// A solid ball of radius 0.5 grown by 3 voxels (the fat model colour carving leaves), points on
// the true sphere, each seen by the cameras on a ring that face it: the sight lines carve the
// fat shell in front of the points and nothing of the true ball.
TEST(CarveFreeSpace, CarvesInFrontOfTheSurfaceAndNothingBehindIt) {
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1)), 64);
  const double radius = 0.5, size = grid.voxel_size();
  Volume ball(grid);
  std::vector<uint64_t> bits((grid.num_voxels() + 63) / 64, 0);
  for (int64_t i = 0; i < grid.num_voxels(); ++i) {
    if (grid.Centre(grid.Voxel(i)).norm() <= radius + 3 * size) bits[i >> 6] |= uint64_t{1} << (i & 63);
  }
  std::vector<CalibratedView> views(12);
  for (int v = 0; v < 12; ++v) {
    const double angle = 2 * M_PI * v / 12;
    views[v].centre = Eigen::Vector3d(3 * std::cos(angle), 3 * std::sin(angle), 0.8);
  }
  std::vector<SurfacePoint> points;
  std::mt19937 random(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int p = 0; p < 400; ++p) {
    SurfacePoint point;
    point.xyz = radius * Eigen::Vector3d(normal(random), normal(random), normal(random)).normalized();
    for (int v = 0; v < 12; ++v) {
      // Seen where the camera lies in front of the tangent plane, not at a grazing angle.
      if ((views[v].centre - point.xyz).normalized().dot(point.xyz.normalized()) > 0.2) point.views.push_back(v);
    }
    if (point.views.size() >= 2) points.push_back(point);
  }
  ASSERT_GT(points.size(), 200u);
  Volume one(grid, bits), three(grid, bits);
  const int64_t before = one.num_solid();
  const FreeSpaceStatistics s1 = CarveFreeSpace(views, points, 2.0, &one, 1);
  const FreeSpaceStatistics s3 = CarveFreeSpace(views, points, 2.0, &three, 3);
  EXPECT_EQ(one.solid_bits(), three.solid_bits()) << "the thread count changed the result";
  EXPECT_EQ(s1.carved, s3.carved);
  EXPECT_EQ(s1.carved, before - one.num_solid());
  EXPECT_GT(s1.sight_lines, static_cast<int64_t>(points.size()));
  int64_t true_carved = 0, straddling_carved = 0, shell = 0, shell_carved = 0;
  for (int64_t i = 0; i < grid.num_voxels(); ++i) {
    const double r = grid.Centre(grid.Voxel(i)).norm();
    const bool was = (bits[i >> 6] >> (i & 63)) & 1u;
    if (!was) continue;
    if (r <= radius - 0.5 * size && !one.IsSolid(i)) ++true_carved;
    if (r <= radius && !one.IsSolid(i)) ++straddling_carved;
    if (r > radius + 1.5 * size) {
      ++shell;
      shell_carved += !one.IsSolid(i);
    }
  }
  EXPECT_EQ(true_carved, 0) << "sight lines carved the true ball";
  // Voxels straddling the sphere (centre less than half a voxel inside) may go where a line
  // grazes the surface 2 voxels short of its point: a few.
  EXPECT_LE(straddling_carved, 10);
  std::printf("carved %lld of %lld shell voxels (centre over 1.5 voxels out), %lld with the centre "
              "inside the true sphere\n", static_cast<long long>(shell_carved),
              static_cast<long long>(shell), static_cast<long long>(straddling_carved));
  // 400 points carve a good share of the shell (their lines are thin: a voxel wide).
  EXPECT_GT(shell_carved, shell / 10) << shell_carved << " of " << shell;
  // The points' own voxels stay.
  for (const SurfacePoint& point : points) EXPECT_TRUE(one.IsSolid(grid.VoxelOf(point.xyz)));
}

TEST(CarveFreeSpace, NoPointsOrAZeroMarginCarveOnlyWhatTheLinesReach) {
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()), 10);
  std::vector<uint64_t> all((grid.num_voxels() + 63) / 64, ~uint64_t{0});
  Volume volume(grid, all);
  std::vector<CalibratedView> views(1);
  views[0].centre = Eigen::Vector3d(0.55, 0.55, 5.0);
  EXPECT_EQ(CarveFreeSpace(views, {}, 2.0, &volume).carved, 0);
  // One point at the grid's middle, seen from above: the column above it goes, down to 2 voxels
  // short of it (the point lies in voxel z = 5; the line stops at z = 0.75, in voxel 7).
  SurfacePoint point;
  point.xyz = Eigen::Vector3d(0.55, 0.55, 0.55);
  point.views = {0};
  const FreeSpaceStatistics s = CarveFreeSpace(views, {point}, 2.0, &volume);
  EXPECT_EQ(s.sight_lines, 1);
  EXPECT_EQ(s.carved, 3);  // z = 7, 8, 9
  for (int z = 0; z < 10; ++z) EXPECT_EQ(volume.IsSolid(Eigen::Vector3i(5, 5, z)), z < 7) << z;
  EXPECT_TRUE(volume.IsSolid(Eigen::Vector3i(4, 5, 9)));
}

// A point under the held ground (a plane at z = 0.5 whose footprint covers x < 0.5) seen from
// above: its line would pass down through the ground, and is not drawn; the same point where the
// line crosses the plane beyond the ground (x > 0.5), or near a hole in it, is drawn.
TEST(CarveFreeSpace, NoSightLinePassesDownThroughTheHeldGround) {
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones()), 10);
  const std::vector<uint64_t> all((grid.num_voxels() + 63) / 64, ~uint64_t{0});
  Ground ground;
  ground.normal = Eigen::Vector3d::UnitZ();
  ground.offset = -0.5;
  ground.depth = 0.05;
  ground.radius = 0.15;
  for (double x = 0.05; x < 0.5; x += 0.1) {
    for (double y = 0.05; y < 1.0; y += 0.1) ground.footprint.emplace_back(x, y, 0.5);
  }
  std::vector<CalibratedView> views(1);
  SurfacePoint point;
  point.xyz = Eigen::Vector3d(0.25, 0.55, 0.25);  // 0.25 under the plane
  point.views = {0};
  views[0].centre = Eigen::Vector3d(0.25, 0.55, 5.0);  // straight above: crosses at x = 0.25
  Volume held(grid, all);
  EXPECT_EQ(CarveFreeSpace(views, {point}, 2.0, &held, 1, ground).sight_lines, 0);
  EXPECT_EQ(held.num_solid(), grid.num_voxels());
  // Without the ground the line is drawn down to two voxels short of the point (z = 0.45).
  Volume open(grid, all);
  EXPECT_EQ(CarveFreeSpace(views, {point}, 2.0, &open, 1).sight_lines, 1);
  EXPECT_FALSE(open.IsSolid(Eigen::Vector3i(2, 5, 5)));
  // A hole in the ground where the line crosses: drawn.
  Ground holed = ground;
  holed.holes.emplace_back(0.25, 0.55, 0.5);
  Volume through_hole(grid, all);
  EXPECT_EQ(CarveFreeSpace(views, {point}, 2.0, &through_hole, 1, holed).sight_lines, 1);
  EXPECT_FALSE(through_hole.IsSolid(Eigen::Vector3i(2, 5, 5)));
  // A point beyond the ground's edge, under the plane (a step down): drawn.
  point.xyz = Eigen::Vector3d(0.85, 0.55, 0.25);
  views[0].centre = Eigen::Vector3d(0.85, 0.55, 5.0);
  Volume beyond(grid, all);
  EXPECT_EQ(CarveFreeSpace(views, {point}, 2.0, &beyond, 1, ground).sight_lines, 1);
  EXPECT_FALSE(beyond.IsSolid(Eigen::Vector3i(8, 5, 5)));
  // A point on the ground (within its depth): drawn.
  point.xyz = Eigen::Vector3d(0.25, 0.55, 0.47);
  views[0].centre = Eigen::Vector3d(0.25, 0.55, 5.0);
  Volume on(grid, all);
  EXPECT_EQ(CarveFreeSpace(views, {point}, 2.0, &on, 1, ground).sight_lines, 1);
}

// A distant pixel's ray carves its whole column; where a sparse point the photo saw lies near
// the pixel, the ray stops two voxels short of it; the voxels to keep stay; a ray with a length
// stops there.
TEST(CarveDistantRays, CarveTheWholeRayOrStopShortOfTheKnownSurface) {
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-0.5), Eigen::Vector3d::Constant(0.5)), 10);
  const std::vector<uint64_t> all((grid.num_voxels() + 63) / 64, ~uint64_t{0});
  const std::vector<CalibratedView> views = {
      testing::PinholeViewLookingAtOrigin(Eigen::Vector3d(0, 0, 5), 100, 100, 100.0)};
  const Eigen::Vector3d target(0.05, 0.05, 0.05);  // in voxel (5, 5, 5)
  const DistantRay ray{0, (target - views[0].centre).normalized()};
  Volume open(grid, all);
  FreeSpaceStatistics s = CarveDistantRays(views, {ray}, {}, 2.0, {}, &open);
  EXPECT_EQ(s.sight_lines, 1);
  EXPECT_EQ(s.carved, 10);
  for (int z = 0; z < 10; ++z) EXPECT_FALSE(open.IsSolid(Eigen::Vector3i(5, 5, z))) << z;
  // The point seen there: the ray stops 2 voxels short of it (at z = 0.05 + 0.2, in voxel 7), and
  // the voxel kept (z = 9) stays.
  SurfacePoint point;
  point.xyz = target;
  point.views = {0};
  Volume stopped(grid, all);
  s = CarveDistantRays(views, {ray}, {point}, 2.0, {grid.Index(Eigen::Vector3i(5, 5, 9))}, &stopped);
  for (int z = 0; z < 10; ++z) EXPECT_EQ(stopped.IsSolid(Eigen::Vector3i(5, 5, z)), z < 7 || z == 9) << z;
  EXPECT_EQ(s.carved, 2);
  // A ground pixel's ray ends where its length does (z = 5 - 4.55 = 0.45, in voxel 9), and a
  // known surface farther along does not carry it on.
  DistantRay ground_ray = ray;
  ground_ray.length = -4.55 / ray.direction.z();
  Volume short_ray(grid, all);
  s = CarveDistantRays(views, {ground_ray}, {point}, 2.0, {}, &short_ray);
  for (int z = 0; z < 10; ++z) EXPECT_EQ(short_ray.IsSolid(Eigen::Vector3i(5, 5, z)), z < 9) << z;
  EXPECT_EQ(s.carved, 1);
  // A ray pointing away from the photo's axis carves nothing.
  Volume behind(grid, all);
  EXPECT_EQ(CarveDistantRays(views, {DistantRay{0, -ray.direction}}, {}, 2.0, {}, &behind).carved, 0);
}

// A distant pixel's ray that passes down through the held ground (a plane at z = -0.1 whose
// footprint covers x < 0) is not drawn: the pixel would show the ground. Past the ground's edge
// (x > 0), or a ray with a length (a ground pixel's), it is.
TEST(CarveDistantRays, NoRayPassesDownThroughTheHeldGround) {
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-0.5), Eigen::Vector3d::Constant(0.5)), 10);
  const std::vector<uint64_t> all((grid.num_voxels() + 63) / 64, ~uint64_t{0});
  const std::vector<CalibratedView> views = {
      testing::PinholeViewLookingAtOrigin(Eigen::Vector3d(0, 0, 5), 100, 100, 100.0)};
  Ground ground;
  ground.normal = Eigen::Vector3d::UnitZ();
  ground.offset = 0.1;
  ground.depth = 0.05;
  ground.radius = 0.15;
  for (double x = -0.45; x < 0.0; x += 0.1) {
    for (double y = -0.45; y < 0.5; y += 0.1) ground.footprint.emplace_back(x, y, -0.1);
  }
  const Eigen::Vector3d on_ground(-0.25, 0.05, -0.1), past_edge(0.25, 0.05, -0.1);
  const DistantRay into_ground{0, (on_ground - views[0].centre).normalized()};
  const DistantRay past{0, (past_edge - views[0].centre).normalized()};
  Volume volume(grid, all);
  FreeSpaceStatistics s =
      CarveDistantRays(views, {into_ground, past}, {}, 2.0, {}, &volume, 1, nullptr, ground);
  EXPECT_EQ(s.sight_lines, 1);
  EXPECT_EQ(s.through_ground, 1);
  EXPECT_TRUE(volume.IsSolid(grid.VoxelOf(on_ground + Eigen::Vector3d(0, 0, 0.3))));
  EXPECT_FALSE(volume.IsSolid(grid.VoxelOf(past_edge + Eigen::Vector3d(0, 0, 0.3))));
  // Without the ground both are drawn; a ray with a length is drawn through it.
  Volume open(grid, all);
  EXPECT_EQ(CarveDistantRays(views, {into_ground, past}, {}, 2.0, {}, &open).sight_lines, 2);
  DistantRay bounded = into_ground;
  bounded.length = (on_ground - views[0].centre).norm();
  Volume bounded_volume(grid, all);
  s = CarveDistantRays(views, {bounded}, {}, 2.0, {}, &bounded_volume, 1, nullptr, ground);
  EXPECT_EQ(s.sight_lines, 1);
  EXPECT_EQ(s.through_ground, 0);
}

}  // namespace
}  // namespace raycarve
