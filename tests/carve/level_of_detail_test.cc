#include "carve/level_of_detail.h"

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

}  // namespace
}  // namespace raycarve
