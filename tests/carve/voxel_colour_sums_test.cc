#include "carve/voxel_colour_sums.h"

#include <random>

#include <gtest/gtest.h>

namespace raycarve {
namespace {

TEST(VoxelColourSums, GiveExactlyTheStatisticsOfThePixelsAddedViewByView) {
  VoxelColourSums sums(/*num_voxels=*/10, /*num_views=*/4);
  std::mt19937 random(3);
  std::uniform_int_distribution<int> byte(0, 255);
  std::vector<ViewColourStats> expected(4);
  for (int view = 0; view < 4; ++view) expected[view].view = view;
  for (int i = 0; i < 500; ++i) {
    const int view = i % 3 == 0 ? 0 : 2;  // views 1 and 3 see nothing
    const uint8_t rgb[3] = {static_cast<uint8_t>(byte(random)), static_cast<uint8_t>(byte(random)),
                            static_cast<uint8_t>(byte(random))};
    sums.Add(7, view, rgb);
    expected[view].Add(Eigen::Vector3d(rgb[0], rgb[1], rgb[2]));
  }
  std::vector<ViewColourStats> stats;
  sums.Stats(7, &stats);
  ASSERT_EQ(stats.size(), 2u);
  for (const ViewColourStats& entry : stats) {
    const ViewColourStats& truth = expected[entry.view];
    EXPECT_EQ(entry.count, truth.count);
    EXPECT_EQ(entry.sum, truth.sum);
    EXPECT_EQ(entry.sum_squares, truth.sum_squares);
  }
  EXPECT_EQ(stats[0].view, 0);
  EXPECT_EQ(stats[1].view, 2);
  sums.Stats(3, &stats);  // never added to
  EXPECT_TRUE(stats.empty());
}

TEST(VoxelColourSums, AReleasedVoxelIsEmptyAndItsSlotIsReusedClean) {
  VoxelColourSums sums(5, 2);
  const uint8_t red[3] = {255, 0, 0};
  sums.Add(1, 1, red);
  sums.Add(2, 0, red);
  EXPECT_EQ(sums.slots_in_use(), 2);
  sums.Release(1);
  sums.Release(1);  // twice is harmless
  EXPECT_EQ(sums.slots_in_use(), 1);
  std::vector<ViewColourStats> stats;
  sums.Stats(1, &stats);
  EXPECT_TRUE(stats.empty());
  const uint8_t blue[3] = {0, 0, 200};
  sums.Add(4, 0, blue);  // takes voxel 1's old slot
  EXPECT_EQ(sums.slots_in_use(), 2);
  sums.Stats(4, &stats);
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_EQ(stats[0].view, 0);
  EXPECT_EQ(stats[0].count, 1);
  EXPECT_EQ(stats[0].sum, Eigen::Vector3d(0, 0, 200));
}

}  // namespace
}  // namespace raycarve
