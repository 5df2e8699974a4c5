#include "carve/layered_depth_visibility.h"

#include <algorithm>
#include <map>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "carve/ray_cast_visibility.h"
#include "tests/carve/carve_fixture.h"

namespace raycarve {
namespace {

using PixelList = std::vector<std::pair<uint32_t, uint32_t>>;
using testing::VisOf;

// Brute force: the surface voxels whose cube the pixel's ray passes through with non-zero length,
// nearest first.
std::vector<int64_t> SurfaceVoxelsAlongRay(const Volume& volume,
                                           const std::vector<int64_t>& surface,
                                           const Eigen::Vector3d& origin,
                                           const Eigen::Vector3d& direction) {
  std::vector<std::pair<double, int64_t>> hits;
  for (const int64_t index : surface) {
    double t = 0.0;
    if (testing::RayEntersVoxel(volume.grid(), volume.grid().Voxel(index), origin, direction, &t)) {
      hits.emplace_back(t, index);
    }
  }
  std::sort(hits.begin(), hits.end());
  std::vector<int64_t> voxels;
  for (const auto& hit : hits) voxels.push_back(hit.second);
  return voxels;
}

// Carves `voxel` from `volume` as the carver does and returns the voxels the lists report changed.
std::vector<int64_t> CarveAndUpdate(int64_t voxel, Volume* volume, LayeredDepthVisibility* ldi) {
  std::vector<PixelRef> vis;
  ldi->ComputeVis(voxel, &vis);
  std::vector<int64_t> exposed, changed;
  volume->Carve(voxel, &exposed);
  ldi->UpdateAfterCarve(voxel, vis, exposed, &changed);
  return changed;
}

TEST(LayeredDepthVisibilityTest, ListsStaySortedAndMatchARebuildAndABruteForceAfterRandomCarvings) {
  const SyntheticScene scene = GenerateSyntheticScene(testing::SceneOptions(4, 64, 48));
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  Volume volume(VoxelGrid(scene.object_box, 12));
  LayeredDepthVisibility ldi(views, volume);

  std::mt19937 random(5);
  int carved = 0, compared_lists = 0, multi_layer = 0;
  for (int round = 0; round < 4; ++round) {
    for (int64_t voxel : volume.SurfaceVoxels()) {
      if (random() % 3 != 0) continue;
      CarveAndUpdate(voxel, &volume, &ldi);
      ++carved;
    }
    const LayeredDepthVisibility rebuilt(views, volume);
    const std::vector<int64_t> surface = volume.SurfaceVoxels();
    EXPECT_EQ(ldi.num_entries(), rebuilt.num_entries()) << "round " << round;
    for (size_t v = 0; v < views.size(); ++v) {
      for (int pixel = 0; pixel < views[v].width * views[v].height; ++pixel) {
        const std::vector<int64_t> list = ldi.List(static_cast<int>(v), pixel);
        ASSERT_EQ(list, rebuilt.List(static_cast<int>(v), pixel))
            << "round " << round << " view " << v << " pixel " << pixel;
        const std::vector<float> depths = ldi.Depths(static_cast<int>(v), pixel);
        ASSERT_TRUE(std::is_sorted(depths.begin(), depths.end())) << "pixel " << pixel;
        for (int64_t voxel : list) ASSERT_TRUE(volume.IsSurface(voxel));
        ASSERT_EQ(list, SurfaceVoxelsAlongRay(volume, surface, views[v].centre,
                                              testing::PixelDirection(views[v], pixel)))
            << "round " << round << " view " << v << " pixel " << pixel;
        ++compared_lists;
        if (list.size() >= 2) ++multi_layer;
      }
    }
  }
  EXPECT_GT(carved, 300);
  EXPECT_GT(compared_lists, 40000);
  EXPECT_GT(multi_layer, 5000);  // the lists are layered, not single items
}

TEST(LayeredDepthVisibilityTest, VisEqualsRayCastingAndCarvingReportsEveryVoxelThatGainsPixels) {
  const SyntheticScene scene = GenerateSyntheticScene(testing::SceneOptions(4, 64, 48));
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  Volume volume(VoxelGrid(scene.object_box, 10));
  LayeredDepthVisibility ldi(views, volume);
  std::mt19937 random(9);
  int checked = 0, gained = 0;
  for (int round = 0; round < 3; ++round) {
    for (int64_t voxel : volume.SurfaceVoxels()) {
      if (random() % 4 != 0) continue;
      // Vis of the whole surface before and after one carving: every voxel whose Vis grew must
      // be reported as changed.
      std::map<int64_t, size_t> before;
      for (int64_t other : volume.SurfaceVoxels()) before[other] = VisOf(&ldi, other).size();
      const std::vector<int64_t> changed = CarveAndUpdate(voxel, &volume, &ldi);
      const std::set<int64_t> reported(changed.begin(), changed.end());
      for (int64_t other : volume.SurfaceVoxels()) {
        if (VisOf(&ldi, other).size() > before[other]) {
          ++gained;
          EXPECT_TRUE(reported.count(other)) << "voxel " << other << " gained pixels unreported";
        }
      }
    }
    // The same Vis(V) as ray casting over the same volume.
    RayCastVisibility rays(views, volume);
    for (int64_t voxel : volume.SurfaceVoxels()) {
      EXPECT_EQ(VisOf(&ldi, voxel), VisOf(&rays, voxel)) << "round " << round << " voxel " << voxel;
      ++checked;
    }
  }
  EXPECT_GT(checked, 500);
  EXPECT_GT(gained, 100);
}

}  // namespace
}  // namespace raycarve
