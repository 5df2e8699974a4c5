#include "carve/visual_hull.h"

#include <gtest/gtest.h>

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
