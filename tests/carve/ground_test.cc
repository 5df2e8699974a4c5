// The ground under an unmasked capture against a plane whose answer is known: a square of floor
// at z = 0 seen from above, with a step down beside it.
#include "carve/ground.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "tests/ground_fixture.h"

namespace raycarve {
namespace {

// The floor's sparse points every 0.1 over the square [-1, 1]^2 at z = 0, its hull the square's
// corners, reaching 0.2; one point seen 0.5 below the plane at (1.5, 1.5) (a step down).
Ground SquareFloor() {
  Ground ground = testing::GridGround(/*axis=*/2, /*half=*/1.0, /*spacing=*/0.1, /*depth=*/0.07,
                                      /*radius=*/0.2, /*outline=*/true);
  ground.holes = {{1.5, 1.5, 0.0}};
  return ground;
}

// Voxels of 0.1 over [-2, 2]^2 x [-1, 1]: centres at odd multiples of 0.05.
const VoxelGrid kGrid(Eigen::AlignedBox3d(Eigen::Vector3d(-2, -2, -1), Eigen::Vector3d(2, 2, 1)), 40);

TEST(GroundVoxels, HoldsWhatLiesUnderTheFloorAndNothingElse) {
  ASSERT_NEAR(kGrid.voxel_size(), 0.1, 1e-12);
  const Ground ground = SquareFloor();
  const std::vector<int64_t> voxels = GroundVoxels(kGrid, ground);
  ASSERT_TRUE(std::is_sorted(voxels.begin(), voxels.end()));
  const std::set<int64_t> held(voxels.begin(), voxels.end());
  int64_t under_square = 0;
  for (int64_t index = 0; index < kGrid.num_voxels(); ++index) {
    const Eigen::Vector3d c = kGrid.Centre(kGrid.Voxel(index));
    const double edge = std::max(std::abs(c.x()), std::abs(c.y()));
    // More than the depth and a voxel (0.17) below the plane, and under the square.
    if (c.z() < -0.17 && edge < 1.06) {
      ++under_square;
      EXPECT_TRUE(held.count(index)) << c.transpose();
    }
    // Never above that, never beyond the square's reach (0.2 and a raster cell).
    if (c.z() > -0.17 || edge > 1.3) {
      EXPECT_FALSE(held.count(index)) << c.transpose();
    }
  }
  EXPECT_EQ(under_square, 22 * 22 * 8);  // centres -1.05..1.05, 8 layers from -0.25 to -0.95
  EXPECT_TRUE(GroundVoxels(kGrid, Ground()).empty());
}

TEST(BeyondGroundVoxels, EmptiesBelowThePlanePastTheFloorButNotNearAPointSeenThere) {
  const Ground ground = SquareFloor();
  const std::vector<int64_t> beyond = BeyondGroundVoxels(kGrid, ground);
  const std::vector<int64_t> held = GroundVoxels(kGrid, ground);
  std::vector<int64_t> both;
  std::set_intersection(beyond.begin(), beyond.end(), held.begin(), held.end(),
                        std::back_inserter(both));
  EXPECT_TRUE(both.empty());
  const std::set<int64_t> empty(beyond.begin(), beyond.end());
  for (int64_t index = 0; index < kGrid.num_voxels(); ++index) {
    const Eigen::Vector3d c = kGrid.Centre(kGrid.Voxel(index));
    const double edge = std::max(std::abs(c.x()), std::abs(c.y()));
    const double to_hole = (c.head<2>() - Eigen::Vector2d(1.5, 1.5)).norm();
    if (c.z() < -0.17 && edge > 1.3 && to_hole > 0.3) {
      EXPECT_TRUE(empty.count(index)) << c.transpose();
    }
    if (c.z() > -0.17 || edge < 1.1 || to_hole < 0.15) {
      EXPECT_FALSE(empty.count(index)) << c.transpose();
    }
  }
}

TEST(GroundMap, TellsGroundHoleAndNeitherApartAndMeasuresHeight) {
  const GroundMap map(SquareFloor());
  EXPECT_EQ(map.At({0.3, -0.7, -0.4}), GroundMap::Foot::kGround);
  EXPECT_EQ(map.At({1.5, 1.45, -0.4}), GroundMap::Foot::kNearHole);
  EXPECT_EQ(map.At({-1.8, 0.0, -0.4}), GroundMap::Foot::kNeither);
  EXPECT_EQ(map.At({1e30, -1e30, 0.0}), GroundMap::Foot::kNeither);  // far away: no overflow
  EXPECT_NEAR(map.Height({0.2, 0.1, -0.35}), -0.35, 1e-12);
  EXPECT_TRUE(map.NearGround({1.3, 0.0, -0.5}, 0.15));   // the square's reach ends near 1.2
  EXPECT_FALSE(map.NearGround({1.7, 0.0, -0.5}, 0.15));
}

TEST(GroundMap, TheOutlineCoversWhatItsPointsLeaveBetweenThem) {
  // Five points on a tilted plane (a pentagon's corners, 3 across), each reaching 0.1: inside the
  // pentagon is ground because its hull says so, not because a point is near.
  Ground ground;
  ground.normal = Eigen::Vector3d(0.0, 0.6, 0.8);
  ground.offset = 0.0;
  ground.radius = 0.1;
  const Eigen::Vector3d u = Eigen::Vector3d::UnitX(), v = ground.normal.cross(u);
  for (int k = 0; k < 5; ++k) {
    const double a = 2.0 * M_PI * k / 5.0;
    ground.footprint.push_back(1.5 * (std::cos(a) * u + std::sin(a) * v));
  }
  ground.outline = ground.footprint;
  const GroundMap map(ground);
  EXPECT_EQ(map.At(Eigen::Vector3d::Zero() - 0.5 * ground.normal), GroundMap::Foot::kGround);
  EXPECT_EQ(map.At(0.9 * v), GroundMap::Foot::kGround);
  EXPECT_EQ(map.At(-1.2 * v), GroundMap::Foot::kGround);   // the pentagon reaches -1.28 there
  EXPECT_EQ(map.At(-1.4 * v), GroundMap::Foot::kNeither);  // beyond its edge and its points' reach
  EXPECT_EQ(map.At(1.7 * u), GroundMap::Foot::kNeither);
  // Without the outline only the points' discs are ground.
  ground.outline.clear();
  EXPECT_EQ(GroundMap(ground).At(Eigen::Vector3d::Zero()), GroundMap::Foot::kNeither);
}

TEST(GroundMap, TheGroundRunsOnPastTheOutlinesEdgesByOneSpacing) {
  // Four points far apart (a square of side 2 at z = 0, reaching 0.2: spacing 0.1): midway along
  // an edge no point is near, but the ground runs on past the edge by a spacing.
  Ground ground;
  ground.normal = Eigen::Vector3d::UnitZ();
  ground.radius = 0.2;
  ground.footprint = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  ground.outline = ground.footprint;
  const GroundMap map(ground);
  EXPECT_EQ(map.At({0.0, -1.08, -0.3}), GroundMap::Foot::kGround);   // 0.08 past the edge
  EXPECT_EQ(map.At({-1.08, 0.3, -0.3}), GroundMap::Foot::kGround);
  EXPECT_EQ(map.At({0.0, -1.15, -0.3}), GroundMap::Foot::kNeither);  // 0.15: past a spacing
  EXPECT_EQ(map.At({1.15, 1.0, -0.3}), GroundMap::Foot::kGround);    // a corner's disc
  EXPECT_EQ(map.At({1.2, 1.2, -0.3}), GroundMap::Foot::kNeither);    // 0.28 from the corner
}

}  // namespace
}  // namespace raycarve
