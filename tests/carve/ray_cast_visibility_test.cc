#include "carve/ray_cast_visibility.h"

#include <map>
#include <random>

#include <gtest/gtest.h>

#include "tests/carve/carve_fixture.h"

namespace raycarve {
namespace {

class RayCastVisibilityTest : public ::testing::TestWithParam<VisLookup> {};

TEST_P(RayCastVisibilityTest, VisAndRaysMatchABruteForceNearestVoxelSearchAfterRandomCarvings) {
  const SyntheticScene scene = GenerateSyntheticScene(testing::SceneOptions(4, 64, 48));
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  Volume volume(VoxelGrid(scene.object_box, 12));
  RayCastVisibility visibility(views, volume, GetParam());

  std::mt19937 random(11);
  std::vector<PixelRef> vis;
  std::vector<int64_t> exposed, changed;
  int carved = 0;
  for (int round = 0; round < 4; ++round) {
    // Carve a random third of the current surface, through the visibility protocol.
    for (int64_t voxel : volume.SurfaceVoxels()) {
      if (random() % 3 != 0) continue;
      vis.clear();
      visibility.ComputeVis(voxel, &vis);
      exposed.clear();
      changed.clear();
      volume.Carve(voxel, &exposed);
      visibility.UpdateAfterCarve(voxel, vis, exposed, &changed);
      for (int64_t next : changed) EXPECT_TRUE(volume.IsSolid(next));
      ++carved;
    }
    // Each ray's current voxel is the nearest solid voxel along it.
    std::map<int64_t, std::vector<std::pair<uint32_t, uint32_t>>> expected_vis;
    int rays_in_box = 0;
    for (size_t v = 0; v < views.size(); ++v) {
      for (int pixel = 0; pixel < views[v].width * views[v].height; ++pixel) {
        const int64_t nearest = testing::NearestSolidVoxel(volume, views[v].centre,
                                                           testing::PixelDirection(views[v], pixel));
        ASSERT_EQ(visibility.rays(v).CurrentVoxel(pixel), nearest)
            << "round " << round << " view " << v << " pixel " << pixel;
        if (nearest >= 0) {
          expected_vis[nearest].emplace_back(static_cast<uint32_t>(v), static_cast<uint32_t>(pixel));
          ++rays_in_box;
        }
      }
    }
    EXPECT_GT(rays_in_box, 1000);
    // Vis(V) from the footprint scan is exactly the pixels whose nearest voxel is V, so each
    // pixel is in at most one voxel's Vis.
    for (int64_t voxel : volume.SurfaceVoxels()) {
      vis.clear();
      visibility.ComputeVis(voxel, &vis);
      std::vector<std::pair<uint32_t, uint32_t>> got;
      for (const PixelRef& ref : vis) got.emplace_back(ref.view, ref.pixel);
      EXPECT_EQ(got, expected_vis[voxel]) << "voxel " << voxel;
    }
  }
  EXPECT_GT(carved, 300);
}

TEST(RayCastVisibility, KeptCountsEqualTheSizeOfVisAfterRandomCarvings) {
  const SyntheticScene scene = GenerateSyntheticScene(testing::SceneOptions(4, 64, 48));
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  Volume volume(VoxelGrid(scene.object_box, 12));
  RayCastVisibility counted(views, volume, VisLookup::kFootprint, /*count_rays=*/true);
  RayCastVisibility plain(views, volume);
  std::mt19937 random(17);
  std::vector<PixelRef> vis;
  std::vector<int64_t> exposed, changed;
  int checked = 0;
  for (int round = 0; round < 3; ++round) {
    for (int64_t voxel : volume.SurfaceVoxels()) {
      if (random() % 3 != 0) continue;
      vis.clear();
      counted.ComputeVis(voxel, &vis);
      exposed.clear();
      changed.clear();
      volume.Carve(voxel, &exposed);
      counted.UpdateAfterCarve(voxel, vis, exposed, &changed);
      plain.UpdateAfterCarve(voxel, vis, exposed, &changed);
    }
    for (int64_t voxel : volume.SurfaceVoxels()) {
      vis.clear();
      plain.ComputeVis(voxel, &vis);
      ASSERT_EQ(counted.CountVis(voxel), static_cast<int64_t>(vis.size())) << voxel;
      ASSERT_EQ(plain.CountVis(voxel), static_cast<int64_t>(vis.size())) << voxel;
      checked += !vis.empty();
    }
  }
  EXPECT_GT(checked, 300);
}

INSTANTIATE_TEST_SUITE_P(BothLookups,
                         RayCastVisibilityTest,
                         ::testing::Values(VisLookup::kFootprint, VisLookup::kRayLists),
                         [](const ::testing::TestParamInfo<VisLookup>& info) {
                           return VisLookupToString(info.param);
                         });

}  // namespace
}  // namespace raycarve
