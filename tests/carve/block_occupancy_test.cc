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

}  // namespace
}  // namespace raycarve
