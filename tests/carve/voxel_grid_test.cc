#include "carve/voxel_grid.h"

#include <gtest/gtest.h>

namespace raycarve {
namespace {

const Eigen::AlignedBox3d kBox(Eigen::Vector3d(-1, 0, 2), Eigen::Vector3d(3, 1, 3.5));

TEST(VoxelGrid, LongestAxisGetsTheResolutionAndVoxelsAreCubes) {
  const VoxelGrid grid(kBox, 80);
  EXPECT_EQ(grid.dimensions(), Eigen::Vector3i(80, 20, 30));
  EXPECT_DOUBLE_EQ(grid.voxel_size(), 0.05);
  EXPECT_EQ(grid.num_voxels(), 80 * 20 * 30);
  EXPECT_TRUE(grid.Box().contains(kBox));
}

TEST(VoxelGrid, ShortAxesRoundUpSoTheBoxIsCovered) {
  const VoxelGrid grid(kBox, 7);  // size 4/7: y needs 1.75 -> 2 voxels, z 2.625 -> 3
  EXPECT_EQ(grid.dimensions(), Eigen::Vector3i(7, 2, 3));
  EXPECT_TRUE(grid.Box().contains(kBox));
  EXPECT_GT(grid.Box().max().y(), kBox.max().y());
}

TEST(VoxelGrid, IndexAndVoxelAreInverse) {
  const VoxelGrid grid(kBox, 16);
  for (int64_t index = 0; index < grid.num_voxels(); index += 7) {
    EXPECT_EQ(grid.Index(grid.Voxel(index)), index);
  }
  EXPECT_EQ(grid.Index(Eigen::Vector3i(1, 2, 3)), 1 + 16 * (2 + 4 * 3));
}

// Voxel size 0.25 so that face coordinates are exact in binary floating point.
TEST(VoxelGrid, PointsOnVoxelFacesBelongToTheUpperVoxel) {
  const VoxelGrid grid(kBox, 16);
  ASSERT_EQ(grid.voxel_size(), 0.25);
  EXPECT_EQ(grid.VoxelOf(Eigen::Vector3d(-1, 0, 2)), Eigen::Vector3i(0, 0, 0));
  EXPECT_EQ(grid.VoxelOf(Eigen::Vector3d(-0.75, 0.25, 2.25)), Eigen::Vector3i(1, 1, 1));
  EXPECT_EQ(grid.VoxelOf(Eigen::Vector3d(-1.0000001, 0, 2)), Eigen::Vector3i(-1, 0, 0));
  EXPECT_EQ(grid.VoxelOf(Eigen::Vector3d(3, 1, 3.5)), Eigen::Vector3i(16, 4, 6));  // max faces: outside
  EXPECT_FALSE(grid.Contains(Eigen::Vector3i(16, 0, 0)));
  EXPECT_FALSE(grid.Contains(Eigen::Vector3i(0, -1, 0)));
  EXPECT_TRUE(grid.Contains(Eigen::Vector3i(15, 3, 5)));
  EXPECT_EQ(grid.Centre(Eigen::Vector3i(0, 0, 0)), Eigen::Vector3d(-0.875, 0.125, 2.125));
  EXPECT_EQ(grid.Corner(Eigen::Vector3i(0, 0, 0), 7), Eigen::Vector3d(-0.75, 0.25, 2.25));
  EXPECT_EQ(grid.Corner(Eigen::Vector3i(0, 0, 0), 2), Eigen::Vector3d(-1, 0.25, 2));
}

TEST(VoxelGrid, TooLargeGridsAreRefusedWithTheMemoryTheyWouldNeed) {
  std::string reason;
  EXPECT_TRUE(CheckGridFits(kBox, 256, 1.0, 1e9, &reason));
  EXPECT_FALSE(CheckGridFits(kBox, 4000, 16.0, 8.0 * (1ull << 30), &reason));
  EXPECT_NE(reason.find("4000x1000x1500"), std::string::npos) << reason;
  EXPECT_NE(reason.find("GiB"), std::string::npos) << reason;
  EXPECT_FALSE(CheckGridFits(kBox, 0, 1.0, 1e9, &reason));
  EXPECT_NE(reason.find("resolution"), std::string::npos);
  EXPECT_FALSE(CheckGridFits(Eigen::AlignedBox3d(), 10, 1.0, 1e9, &reason));
}

}  // namespace
}  // namespace raycarve
