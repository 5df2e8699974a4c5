#include "carve/block_occupancy.h"

#include <random>

#include <gtest/gtest.h>

namespace raycarve {
namespace {

TEST(BlockOccupancy, MarksExactlyTheBlocksHoldingASolidVoxelIncludingPartialEdgeBlocks) {
  // 10x7x5 voxels: 3x2x2 blocks, the last along each axis partial.
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0.7, 0.5)),
                       10);
  ASSERT_EQ(grid.dimensions(), Eigen::Vector3i(10, 7, 5));
  std::mt19937_64 random(3);
  for (int trial = 0; trial < 30; ++trial) {
    std::vector<uint64_t> solid((grid.num_voxels() + 63) / 64, 0);
    std::bernoulli_distribution pick(trial % 3 == 0 ? 0.0 : 0.01 * trial);
    for (int64_t index = 0; index < grid.num_voxels(); ++index) {
      if (pick(random)) solid[index >> 6] |= uint64_t{1} << (index & 63);
    }
    const Volume volume(grid, solid);
    const BlockOccupancy blocks(volume);
    ASSERT_EQ(blocks.dimensions(), Eigen::Vector3i(3, 2, 2));
    int64_t occupied = 0;
    for (int z = 0; z < 2; ++z) {
      for (int y = 0; y < 2; ++y) {
        for (int x = 0; x < 3; ++x) {
          bool any = false;  // brute force over the block's voxels
          for (int64_t index = 0; index < grid.num_voxels(); ++index) {
            const Eigen::Vector3i v = grid.Voxel(index);
            any |= volume.IsSolid(index) && v.x() / 4 == x && v.y() / 4 == y && v.z() / 4 == z;
          }
          EXPECT_EQ(blocks.IsOccupied(x, y, z), any) << "trial " << trial;
          occupied += any;
        }
      }
    }
    EXPECT_EQ(blocks.num_occupied(), occupied);
    EXPECT_EQ(blocks.num_blocks(), 12);
  }
}

TEST(BlockOccupancy, TheBoundaryIsTheOccupiedBlocksBesideAnEmptyOneOrOnTheEdge) {
  // 16 voxels a side: 4x4x4 blocks.
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 1, 1)), 16);
  ASSERT_EQ(grid.dimensions(), Eigen::Vector3i(16, 16, 16));
  // All solid: the 56 blocks on the edge; the 2x2x2 inside are hidden behind them.
  const BlockOccupancy full(Volume(grid, std::vector<uint64_t>(grid.num_voxels() / 64, ~0ull)));
  EXPECT_EQ(full.boundary().size(), 56u);
  for (const Eigen::Vector3i& block : full.boundary()) {
    EXPECT_TRUE((block.array() == 0).any() || (block.array() == 3).any()) << block.transpose();
  }
  // One solid voxel inside: its block alone. A 2x2x2 cube of blocks inside: all 8 (each has an
  // empty neighbour).
  std::vector<uint64_t> one(grid.num_voxels() / 64, 0);
  const int64_t voxel = grid.Index(Eigen::Vector3i(5, 9, 6));
  one[voxel >> 6] |= uint64_t{1} << (voxel & 63);
  const BlockOccupancy single((Volume(grid, one)));
  ASSERT_EQ(single.boundary().size(), 1u);
  EXPECT_EQ(single.boundary()[0], Eigen::Vector3i(1, 2, 1));
  std::vector<uint64_t> cube(grid.num_voxels() / 64, 0);
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    const Eigen::Vector3i v = grid.Voxel(index);
    if ((v.array() >= 4).all() && (v.array() < 12).all()) cube[index >> 6] |= uint64_t{1} << (index & 63);
  }
  const BlockOccupancy inner((Volume(grid, cube)));
  EXPECT_EQ(inner.num_occupied(), 8);
  EXPECT_EQ(inner.boundary().size(), 8u);
}

}  // namespace
}  // namespace raycarve
