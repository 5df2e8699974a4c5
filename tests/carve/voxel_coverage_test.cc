#include "carve/voxel_coverage.h"

#include <algorithm>

#include <gtest/gtest.h>

#include "carve/ray_image.h"
#include "tests/carve/carve_fixture.h"

namespace raycarve {
namespace {

TEST(VoxelCoverage, DrawsExactlyThePixelsWhoseRaysEnterTheVoxelWithTheirEntryDepth) {
  const SyntheticScene scene = GenerateSyntheticScene(testing::SceneOptions(3, 80, 60));
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  const VoxelGrid grid(scene.object_box, 9);
  int covered = 0, outside_projection_in_box = 0;
  for (const CalibratedView& view : views) {
    const VoxelCoverage coverage(view, grid);
    for (int64_t index = 0; index < grid.num_voxels(); index += 7) {
      const Eigen::Vector3i voxel = grid.Voxel(index);
      std::vector<int> drawn;
      coverage.ForEach(voxel, [&](int pixel, double t) {
        drawn.push_back(pixel);
        double t_world = 0.0;
        ASSERT_TRUE(testing::RayEntersVoxel(grid, voxel, view.centre, testing::PixelDirection(view, pixel),
                              &t_world));
        // Grid units scale the origin and the direction alike: the same ray parameter.
        EXPECT_NEAR(t, t_world, 1e-6 * std::max(1.0, t_world)) << "pixel " << pixel;
      });
      covered += static_cast<int>(drawn.size());
      // Every pixel of the footprint's box not drawn is missed by its ray.
      const Footprint footprint = ComputeFootprint(view.P, view.width, view.height, grid, voxel);
      for (int row = footprint.row_min; row <= footprint.row_max; ++row) {
        for (int col = footprint.col_min; col <= footprint.col_max; ++col) {
          const int pixel = row * view.width + col;
          if (std::find(drawn.begin(), drawn.end(), pixel) != drawn.end()) continue;
          double t = 0.0;
          EXPECT_FALSE(testing::RayEntersVoxel(grid, voxel, view.centre, testing::PixelDirection(view, pixel), &t))
              << "pixel " << pixel << " of voxel " << index << " not drawn";
          ++outside_projection_in_box;
        }
      }
    }
  }
  EXPECT_GT(covered, 2000);
  // The bounding box holds pixels outside the cube's true projection, and they were left out.
  EXPECT_GT(outside_projection_in_box, 200);
}

TEST(VoxelCoverage, LeavesOutPixelsWithoutPhotoDataOrOffTheMask) {
  const SyntheticScene scene = GenerateSyntheticScene(testing::SceneOptions(2, 80, 60));
  std::vector<CalibratedView> views = testing::SceneViews(scene, /*with_masks=*/true);
  const VoxelGrid grid(scene.object_box, 6);
  CalibratedView& view = views[0];
  view.valid(cv::Rect(0, 0, 40, 60)).setTo(0);  // the left half has no photo data
  const VoxelCoverage coverage(view, grid);
  int drawn = 0;
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    coverage.ForEach(grid.Voxel(index), [&](int pixel, double) {
      ++drawn;
      EXPECT_GE(pixel % view.width, 40);
      EXPECT_NE(view.mask.data[pixel], 0);
    });
  }
  EXPECT_GT(drawn, 100);
}

}  // namespace
}  // namespace raycarve
