#include "carve/level_of_detail.h"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

namespace raycarve {
namespace {

TEST(LevelOfDetail, ResolutionsHalveDownToTheCoarsestAndRefuseWhatCannotHalve) {
  std::vector<int> resolutions;
  std::string reason;
  ASSERT_TRUE(LevelResolutions(128, 3, &resolutions, &reason));
  EXPECT_EQ(resolutions, (std::vector<int>{32, 64, 128}));
  ASSERT_TRUE(LevelResolutions(100, 1, &resolutions, &reason));
  EXPECT_EQ(resolutions, (std::vector<int>{100}));
  EXPECT_FALSE(LevelResolutions(100, 4, &resolutions, &reason));
  EXPECT_NE(reason.find("divisible by 8"), std::string::npos) << reason;
  EXPECT_FALSE(LevelResolutions(16, 4, &resolutions, &reason));
  EXPECT_NE(reason.find("coarsest level would have 2"), std::string::npos) << reason;
  EXPECT_FALSE(LevelResolutions(128, 9, &resolutions, &reason));
}

TEST(LevelOfDetail, AutomaticLevelsKeepTheCoarsestAtSixtyFourVoxelsOrMore) {
  EXPECT_EQ(AutomaticLevels(64), 1);
  EXPECT_EQ(AutomaticLevels(96), 1);   // 48 would be too coarse
  EXPECT_EQ(AutomaticLevels(127), 1);  // odd: cannot halve
  EXPECT_EQ(AutomaticLevels(128), 2);
  EXPECT_EQ(AutomaticLevels(200), 2);  // 100; 50 would be too coarse
  EXPECT_EQ(AutomaticLevels(256), 3);
  EXPECT_EQ(AutomaticLevels(1024), 5);
  EXPECT_EQ(AutomaticLevels(1 << 12), 7);
  EXPECT_EQ(AutomaticLevels(1 << 14), 8);  // at most 8 levels
  std::vector<int> resolutions;
  std::string reason;
  ASSERT_TRUE(LevelResolutions(256, kAutomaticLevels, &resolutions, &reason)) << reason;
  EXPECT_EQ(resolutions, (std::vector<int>{64, 128, 256}));
  ASSERT_TRUE(LevelResolutions(24, kAutomaticLevels, &resolutions, &reason)) << reason;
  EXPECT_EQ(resolutions, (std::vector<int>{24}));
  EXPECT_FALSE(LevelResolutions(128, -1, &resolutions, &reason));
  EXPECT_NE(reason.find("0: automatic"), std::string::npos) << reason;
}

TEST(LevelOfDetail, RefinementKeepsExactlyTheChildrenOfVoxelsNearWhatSurvived) {
  // An elongated box: the fine grid has fewer than twice the coarse voxels on the short axes.
  const Eigen::AlignedBox3d box(Eigen::Vector3d(-1.0, 0.0, 0.2), Eigen::Vector3d(2.0, 1.3, 0.9));
  const VoxelGrid coarse_grid(box, 12), fine_grid(box, 24);
  ASSERT_TRUE((fine_grid.dimensions().array() <= 2 * coarse_grid.dimensions().array()).all());
  std::mt19937 random(4);
  for (const int band : {0, 1, 2}) {
    Volume coarse(coarse_grid);
    for (int64_t i = 0; i < coarse_grid.num_voxels(); ++i) {
      if (random() % 10 != 0) coarse.Carve(i, nullptr);  // about a tenth survives
    }
    const Volume fine = RefineVolume(coarse, fine_grid, band);
    int solid = 0;
    for (int64_t i = 0; i < fine_grid.num_voxels(); ++i) {
      const Eigen::Vector3i parent = fine_grid.Voxel(i) / 2;
      bool near = false;
      for (int64_t j = 0; j < coarse_grid.num_voxels() && !near; ++j) {
        if (!coarse.IsSolid(j)) continue;
        const Eigen::Vector3i d = coarse_grid.Voxel(j) - parent;
        near = d.cwiseAbs().maxCoeff() <= band;
      }
      ASSERT_EQ(fine.IsSolid(i), near) << "band " << band << " voxel " << i;
      ASSERT_EQ(fine.IsSurface(i), fine.IsExposed(i)) << "band " << band << " voxel " << i;
      solid += near;
    }
    EXPECT_EQ(fine.num_solid(), solid);
    EXPECT_GT(solid, 0);
    EXPECT_LT(solid, fine_grid.num_voxels());
  }
}

TEST(LevelOfDetail, OnlyVoxelsDeeperThanTheCarveDepthInsideTheCoarseSolidAreHeld) {
  // A solid cube of 6 coarse voxels in a grid of 10: at depth 1 its inner 4^3, at depth 2 its
  // inner 2^3 are held, each as its 8 children.
  const Eigen::AlignedBox3d cube(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
  const VoxelGrid coarse_grid(cube, 10), fine_grid(cube, 20);
  Volume coarse(coarse_grid);
  for (int64_t i = 0; i < coarse_grid.num_voxels(); ++i) {
    const Eigen::Vector3i v = coarse_grid.Voxel(i);
    if ((v.array() < 2).any() || (v.array() >= 8).any()) coarse.Carve(i, nullptr);
  }
  EXPECT_TRUE(DeepInteriorVoxels(coarse, fine_grid, 0).empty());
  for (const int depth : {1, 2}) {
    const std::vector<int64_t> held = DeepInteriorVoxels(coarse, fine_grid, depth);
    const int side = 6 - 2 * depth;
    ASSERT_EQ(held.size(), static_cast<size_t>(side * side * side * 8)) << "depth " << depth;
    EXPECT_TRUE(std::is_sorted(held.begin(), held.end()));
    for (int64_t i : held) {
      const Eigen::Vector3i parent = fine_grid.Voxel(i) / 2;
      EXPECT_TRUE((parent.array() >= 2 + depth).all() && (parent.array() < 8 - depth).all())
          << "depth " << depth << " voxel " << i;
    }
  }
  // The grid's edge counts as carved: a volume solid everywhere holds all but its outer layers.
  const Volume full(coarse_grid,
                    std::vector<uint64_t>((coarse_grid.num_voxels() + 63) / 64, ~0ull));
  ASSERT_EQ(full.num_solid(), coarse_grid.num_voxels());
  EXPECT_EQ(DeepInteriorVoxels(full, fine_grid, 1).size(), static_cast<size_t>(8 * 8 * 8 * 8));

  // A region of the fine grid holds what the whole grid holds there, in the region's indices.
  std::mt19937 random(7);
  Volume scattered(coarse_grid);
  for (int64_t i = 0; i < coarse_grid.num_voxels(); ++i) {
    if (random() % 12 == 0) scattered.Carve(i, nullptr);
  }
  const Eigen::Vector3i lo(4, 6, 2), hi(14, 20, 11);
  const VoxelGrid region = fine_grid.Region(lo, hi);
  const std::vector<int64_t> whole = DeepInteriorVoxels(scattered, fine_grid, 1);
  std::vector<int64_t> expected;
  for (int64_t i : whole) {
    const Eigen::Vector3i v = fine_grid.Voxel(i);
    if ((v.array() >= lo.array()).all() && (v.array() < hi.array()).all()) {
      expected.push_back(region.Index(v - lo));
    }
  }
  ASSERT_FALSE(expected.empty());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(DeepInteriorRegion(scattered, region, lo, 1), expected);
}

}  // namespace
}  // namespace raycarve
