#include "carve/voxel_coverage.h"

#include <algorithm>

#include <gtest/gtest.h>

#include "carve/ray_image.h"
#include "tests/carve/carve_fixture.h"

namespace raycarve {
namespace {

// Brute force: whether the ray of a pixel passes through the voxel's cube with non-zero length,
// and where it enters (world units along the pixel direction of carve_fixture.h).
bool RayEnters(const VoxelGrid& grid, const Eigen::Vector3i& voxel, const Eigen::Vector3d& origin,
               const Eigen::Vector3d& direction, double* t_enter) {
  const Eigen::Vector3d lo = grid.Corner(voxel, 0), hi = grid.Corner(voxel, 7);
  double t0 = 0.0, t1 = 1e300;
  for (int axis = 0; axis < 3; ++axis) {
    double a = (lo[axis] - origin[axis]) / direction[axis];
    double b = (hi[axis] - origin[axis]) / direction[axis];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  *t_enter = t0;
  return t1 - t0 > 1e-9;
}

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
        ASSERT_TRUE(RayEnters(grid, voxel, view.centre, testing::PixelDirection(view, pixel),
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
          EXPECT_FALSE(RayEnters(grid, voxel, view.centre, testing::PixelDirection(view, pixel), &t))
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
