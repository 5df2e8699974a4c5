#include "carve/item_buffer_visibility.h"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "carve/ray_cast_visibility.h"
#include "tests/carve/carve_fixture.h"

namespace raycarve {
namespace {

using PixelList = std::vector<std::pair<uint32_t, uint32_t>>;
using testing::VisOf;

TEST(ItemBufferVisibilityTest, FreshBuffersGiveRayCastingsVisAndStaleOnesASubsetOfIt) {
  const SyntheticScene scene = GenerateSyntheticScene(testing::SceneOptions(4, 64, 48));
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  Volume volume(VoxelGrid(scene.object_box, 12));
  ItemBufferVisibility gvc(views, volume);
  EXPECT_FALSE(gvc.StartPass()) << "nothing carved: no new pass";
  EXPECT_EQ(gvc.renders(), 1);

  std::mt19937 random(3);
  std::vector<PixelRef> vis;
  std::vector<int64_t> exposed, changed;
  int compared = 0, stale_smaller = 0;
  for (int round = 0; round < 4; ++round) {
    for (int64_t voxel : volume.SurfaceVoxels()) {
      if (random() % 3 != 0) continue;
      vis.clear();
      gvc.ComputeVis(voxel, &vis);
      exposed.clear();
      changed.clear();
      volume.Carve(voxel, &exposed);
      gvc.UpdateAfterCarve(voxel, vis, exposed, &changed);
      EXPECT_TRUE(changed.empty()) << "GVC learns of changes only at the next pass";
    }
    // Stale buffers: every surface voxel's Vis is a subset of its true Vis (never a wrong carve).
    RayCastVisibility rays(views, volume);
    for (int64_t voxel : volume.SurfaceVoxels()) {
      const PixelList stale = VisOf(&gvc, voxel), truth = VisOf(&rays, voxel);
      EXPECT_TRUE(std::includes(truth.begin(), truth.end(), stale.begin(), stale.end()))
          << "voxel " << voxel;
      if (stale.size() < truth.size()) ++stale_smaller;
    }
    ASSERT_TRUE(gvc.StartPass());
    for (int64_t voxel : volume.SurfaceVoxels()) {
      EXPECT_EQ(VisOf(&gvc, voxel), VisOf(&rays, voxel)) << "round " << round << " voxel " << voxel;
      ++compared;
    }
  }
  EXPECT_EQ(gvc.renders(), 5);
  EXPECT_GT(compared, 1000);
  EXPECT_GT(stale_smaller, 50);  // the stale buffers did miss pixels: the subset check had teeth
}

}  // namespace
}  // namespace raycarve
