#include "carve/volume.h"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

namespace raycarve {
namespace {

TEST(Volume, StartsSolidWithTheBorderAsSurface) {
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(5, 4, 3)), 5);
  const Volume volume(grid);
  EXPECT_EQ(volume.num_solid(), 60);
  EXPECT_EQ(volume.num_surface(), 60 - 3 * 2 * 1);  // interior 3x2x1
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    EXPECT_EQ(volume.IsSurface(index), volume.IsExposed(index)) << index;
  }
  EXPECT_EQ(volume.SurfaceVoxels().size(), 54u);
}

TEST(Volume, CarvingExposesExactlyTheInteriorNeighboursAndKeepsTheSurfaceExact) {
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1)), 9);
  Volume volume(grid);
  std::mt19937 random(7);
  std::vector<int64_t> order(grid.num_voxels());
  for (int64_t i = 0; i < grid.num_voxels(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), random);
  int64_t carved = 0;
  for (int64_t voxel : order) {
    if (!volume.IsSurface(voxel) || random() % 3 == 0) continue;  // carve from the outside in
    std::vector<bool> was_surface(grid.num_voxels());
    for (int64_t i = 0; i < grid.num_voxels(); ++i) was_surface[i] = volume.IsSurface(i);
    std::vector<int64_t> exposed;
    volume.Carve(voxel, &exposed);
    ++carved;
    EXPECT_FALSE(volume.IsSolid(voxel));
    EXPECT_FALSE(volume.IsSurface(voxel));
    std::vector<int64_t> expected;
    for (int64_t i = 0; i < grid.num_voxels(); ++i) {
      ASSERT_EQ(volume.IsSurface(i), volume.IsExposed(i)) << "voxel " << i << " after carving " << voxel;
      if (volume.IsSurface(i) && !was_surface[i]) expected.push_back(i);
    }
    std::sort(exposed.begin(), exposed.end());
    EXPECT_EQ(exposed, expected);
  }
  EXPECT_GT(carved, 100);
  EXPECT_EQ(volume.num_solid(), grid.num_voxels() - carved);
  EXPECT_EQ(volume.num_surface(), static_cast<int64_t>(volume.SurfaceVoxels().size()));
}

TEST(Volume, VoxelsOnTheGridEdgeAreSurfaceAndStayInsideTheGrid) {
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(3, 1, 1)), 3);
  Volume volume(grid);
  ASSERT_EQ(grid.dimensions(), Eigen::Vector3i(3, 1, 1));
  std::vector<int64_t> exposed;
  volume.Carve(grid.Index(Eigen::Vector3i(0, 0, 0)), &exposed);
  EXPECT_TRUE(exposed.empty());  // every voxel of a 3x1x1 grid is on the border already
  EXPECT_FALSE(volume.IsSolid(Eigen::Vector3i(-1, 0, 0)));  // outside the grid: not solid
}

}  // namespace
}  // namespace raycarve
