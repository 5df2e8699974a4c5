#include "carve/visual_hull.h"

#include <gtest/gtest.h>

#include "carve/footprint.h"
#include "tests/carve/carve_fixture.h"

namespace raycarve {
namespace {

SyntheticScene BackdropScene() {
  return GenerateSyntheticScene(testing::SceneOptions(8, 160, 120, /*uniform_backdrop=*/true));
}

TEST(VisualHull, KeepsEveryVoxelOfTheTrueSurfaceAndRemovesMostEmptySpace) {
  const SyntheticScene scene = BackdropScene();
  const std::vector<CalibratedView> views = testing::SceneViews(scene, /*with_masks=*/true);
  Eigen::AlignedBox3d box = scene.object_box;
  box.extend(box.max() + Eigen::Vector3d(0.3, 0.3, 0.6));  // room above and beside the objects
  box.extend(box.min() - Eigen::Vector3d(0.3, 0.3, 0.3));
  Volume volume(VoxelGrid(box, 48));
  const VisualHullStatistics statistics = CarveVisualHull(views, &volume);
  EXPECT_EQ(statistics.views_with_masks, 8);
  EXPECT_EQ(statistics.carved, volume.grid().num_voxels() - volume.num_solid());
  EXPECT_GT(statistics.carved, volume.grid().num_voxels() / 2);
  // Conservative: every voxel holding a visible true surface point survives.
  const std::vector<Eigen::Vector3d> truth = SampleTrueSurface(scene, 20000, 3, 2);
  ASSERT_GT(truth.size(), 5000u);
  int lost = 0;
  for (const Eigen::Vector3d& point : truth) {
    lost += !volume.IsSolid(volume.grid().VoxelOf(point));
  }
  EXPECT_EQ(lost, 0);
  // The incremental surface stays exact after the pre-carve.
  for (int64_t i = 0; i < volume.grid().num_voxels(); ++i) {
    ASSERT_EQ(volume.IsSurface(i), volume.IsExposed(i)) << i;
  }
  // Judged on 3 threads: the same voxels.
  Volume threaded(VoxelGrid(box, 48));
  EXPECT_EQ(CarveVisualHull(views, &threaded, 3).carved, statistics.carved);
  for (int64_t i = 0; i < volume.grid().num_voxels(); ++i) {
    ASSERT_EQ(threaded.IsSolid(i), volume.IsSolid(i)) << i;
  }
  // Two views needed to carve (the voting hull of AgreeMasks): it holds the plain hull, and
  // still carves most of the empty space.
  Volume voting(VoxelGrid(box, 48));
  const VisualHullStatistics votes = CarveVisualHull(views, &voting, 2, /*min_background_views=*/2);
  EXPECT_LT(votes.carved, statistics.carved);
  EXPECT_GT(votes.carved, volume.grid().num_voxels() / 3);
  for (int64_t i = 0; i < volume.grid().num_voxels(); ++i) {
    if (volume.IsSolid(i)) {
      ASSERT_TRUE(voting.IsSolid(i)) << i;
    }
  }
}

// Brute force: whether some masked view shows the voxel entirely on background, its footprint
// inside the image and every one of its pixels checked one by one.
bool OutsideByPixels(const std::vector<CalibratedView>& views, const VoxelGrid& grid,
                     const Eigen::Vector3i& voxel) {
  for (const CalibratedView& view : views) {
    const Footprint f = ComputeFootprint(view.P, 1 << 20, 1 << 20, grid, voxel);
    if (f.empty() || f.col_min <= 0 || f.row_min <= 0 || f.col_max >= view.width ||
        f.row_max >= view.height) {
      continue;
    }
    bool valid = false, object = false;
    for (int row = f.row_min; row <= f.row_max; ++row) {
      for (int col = f.col_min; col <= f.col_max; ++col) {
        if (view.valid.at<uint8_t>(row, col) == 0) continue;
        valid = true;
        // The silhouette grown by one pixel.
        for (int dr = -1; dr <= 1; ++dr) {
          for (int dc = -1; dc <= 1; ++dc) {
            const int r = row + dr, c = col + dc;
            if (r >= 0 && c >= 0 && r < view.height && c < view.width &&
                view.mask.at<uint8_t>(r, c) != 0) {
              object = true;
            }
          }
        }
      }
    }
    if (valid && !object) return true;
  }
  return false;
}

TEST(VisualHull, CarvesExactlyTheVoxelsThatSomeViewShowsOnBackgroundPixelByPixel) {
  const SyntheticScene scene = BackdropScene();
  const std::vector<CalibratedView> views = testing::SceneViews(scene, /*with_masks=*/true);
  Eigen::AlignedBox3d box = scene.object_box;
  box.extend(box.max() + Eigen::Vector3d(0.3, 0.3, 0.6));
  box.extend(box.min() - Eigen::Vector3d(0.3, 0.3, 0.3));
  // A full volume, and one with half its voxels already carved (a checkerboard of 3x3x3 cubes,
  // as a coarser level may leave), on a grid whose sides are not multiples of 4.
  const VoxelGrid grid(box, 37);
  for (bool partial : {false, true}) {
    Volume volume(grid);
    if (partial) {
      for (int64_t index = 0; index < grid.num_voxels(); ++index) {
        const Eigen::Vector3i v = grid.Voxel(index) / 3;
        if ((v.x() + v.y() + v.z()) % 2 == 1) volume.Carve(index, nullptr);
      }
    }
    const Volume before = volume;
    const VisualHullStatistics statistics = CarveVisualHull(views, &volume, 2);
    int64_t carved = 0, kept = 0;
    for (int64_t index = 0; index < grid.num_voxels(); ++index) {
      if (!before.IsSolid(index)) continue;
      const bool outside = OutsideByPixels(views, grid, grid.Voxel(index));
      ASSERT_EQ(volume.IsSolid(index), !outside) << "voxel " << grid.Voxel(index).transpose();
      carved += outside;
      kept += !outside;
    }
    EXPECT_EQ(statistics.carved, carved);
    EXPECT_GT(carved, 1000);
    EXPECT_GT(kept, 1000);
  }
}

TEST(VisualHull, ViewsWithoutMasksChangeNothing) {
  const SyntheticScene scene = BackdropScene();
  Volume volume(VoxelGrid(scene.object_box, 24));
  const VisualHullStatistics statistics = CarveVisualHull(testing::SceneViews(scene), &volume);
  EXPECT_EQ(statistics.views_with_masks, 0);
  EXPECT_EQ(statistics.carved, 0);
  EXPECT_EQ(volume.num_solid(), volume.grid().num_voxels());
}

}  // namespace
}  // namespace raycarve
