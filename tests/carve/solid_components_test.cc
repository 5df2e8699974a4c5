// Connected pieces of the model: small components and pieces without the sparse points their size
// predicts are carved, and the rays that ended in them step on.
#include "carve/carver.h"
#include "carve/incremental_carver.h"

#include <algorithm>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "carve/ray_cast_visibility.h"
#include "tests/carve/carve_fixture.h"

namespace raycarve {
namespace {
using testing::Options;
using testing::Scene;

// Six views of the generated scene, a grid of 24 voxels over its box, and the bits of a volume
// on it whose voxels the test sets one by one.
class SolidComponents : public ::testing::Test {
 protected:
  SolidComponents()
      : scene_(Scene(6, 120, 90)),
        views_(testing::SceneViews(scene_)),
        grid_(scene_.object_box, 24),
        bits_((grid_.num_voxels() + 63) / 64, 0) {}

  void Set(int x, int y, int z) {
    const int64_t i = grid_.Index(Eigen::Vector3i(x, y, z));
    bits_[i >> 6] |= uint64_t{1} << (i & 63);
  }
  // The volume of the voxels set so far (once).
  Volume TakeVolume() { return Volume(grid_, std::move(bits_)); }

  const SyntheticScene scene_;
  const std::vector<CalibratedView> views_;
  const VoxelGrid grid_;
  std::vector<uint64_t> bits_;
};

TEST_F(SolidComponents, SmallComponentsAreCarvedAndTheirRaysStepOn) {
  const std::vector<CalibratedView>& views = views_;
  const VoxelGrid& grid = grid_;
  // A slab along the bottom (one big component), a lone voxel, a diagonal pair (26-connected:
  // one component of 2) and a 3x3x3 cube, all in empty space.
  const auto set = [&](int x, int y, int z) { Set(x, y, z); };
  const Eigen::Vector3i& n = grid.dimensions();
  for (int y = 0; y < n.y(); ++y) {
    for (int x = 0; x < n.x(); ++x) set(x, y, 0), set(x, y, 1);
  }
  set(5, 5, 6);
  set(12, 12, 5), set(13, 13, 6);
  for (int z = 4; z < 7; ++z) {
    for (int y = 16; y < 19; ++y) {
      for (int x = 16; x < 19; ++x) set(x, y, z);
    }
  }
  IncrementalCarver carver(views, TakeVolume(), Options(24, 30.0));
  const int64_t slab = 2 * static_cast<int64_t>(n.x()) * n.y();
  ASSERT_EQ(carver.volume().num_solid(), slab + 1 + 2 + 27);
  // Before any carving, so that the specks still stop rays. Components of 1 and 2 voxels go with
  // a bound of 3; the cube of 27 stays until the bound is 28.
  EXPECT_EQ(carver.RemoveSmallComponents(3), 3);
  EXPECT_FALSE(carver.volume().IsSolid(Eigen::Vector3i(5, 5, 6)));
  EXPECT_FALSE(carver.volume().IsSolid(Eigen::Vector3i(12, 12, 5)));
  EXPECT_FALSE(carver.volume().IsSolid(Eigen::Vector3i(13, 13, 6)));
  EXPECT_TRUE(carver.volume().IsSolid(Eigen::Vector3i(17, 17, 5)));
  EXPECT_EQ(carver.RemoveSmallComponents(27), 0);
  EXPECT_EQ(carver.RemoveSmallComponents(28), 27);
  EXPECT_EQ(carver.volume().num_solid(), slab);
  // Every ray that ended in a removed voxel has stepped on: rays end in solid voxels only.
  int on_slab = 0;
  for (int view = 0; view < static_cast<int>(views.size()); ++view) {
    const RayImage& rays = carver.ray_visibility()->rays(view);
    for (int pixel = 0; pixel < rays.num_pixels(); ++pixel) {
      const int64_t voxel = rays.CurrentVoxel(pixel);
      ASSERT_TRUE(voxel == RayImage::kNoVoxel || carver.volume().IsSolid(voxel)) << pixel;
      on_slab += voxel != RayImage::kNoVoxel;
    }
  }
  EXPECT_GT(on_slab, 1000);
  // The slab is one component of far more voxels: it stays.
  EXPECT_EQ(carver.RemoveSmallComponents(28), 0);
  while (carver.Step()) {
  }
  EXPECT_GT(carver.evaluated(), 0);
}

// Random solid voxels (9% of a 24-voxel grid, near where 26-neighbour clusters join up: lone
// voxels, clumps touching along edges and corners, some large): the components that
// RemoveSmallComponents finds are those of a plain breadth-first search over the 26 neighbours,
// for every size bound.
TEST_F(SolidComponents, ComponentsAreThoseOfABreadthFirstSearch) {
  const VoxelGrid& grid = grid_;
  std::mt19937 random(11);
  std::bernoulli_distribution solid(0.09);
  std::vector<uint8_t> is_solid(grid.num_voxels(), 0);
  for (int64_t i = 0; i < grid.num_voxels(); ++i) {
    if (!solid(random)) continue;
    is_solid[i] = 1;
    const Eigen::Vector3i voxel = grid.Voxel(i);
    Set(voxel.x(), voxel.y(), voxel.z());
  }
  // The reference: component sizes by breadth-first search.
  std::vector<int> label(grid.num_voxels(), -1);
  std::vector<int64_t> sizes;
  for (int64_t start = 0; start < grid.num_voxels(); ++start) {
    if (!is_solid[start] || label[start] >= 0) continue;
    const int id = static_cast<int>(sizes.size());
    std::vector<int64_t> queue{start};
    label[start] = id;
    for (size_t k = 0; k < queue.size(); ++k) {
      const Eigen::Vector3i voxel = grid.Voxel(queue[k]);
      for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const Eigen::Vector3i next = voxel + Eigen::Vector3i(dx, dy, dz);
            if (!grid.Contains(next)) continue;
            const int64_t index = grid.Index(next);
            if (is_solid[index] && label[index] < 0) {
              label[index] = id;
              queue.push_back(index);
            }
          }
        }
      }
    }
    sizes.push_back(static_cast<int64_t>(queue.size()));
  }
  ASSERT_GT(std::count(sizes.begin(), sizes.end(), 1), 10);
  ASSERT_GT(std::count_if(sizes.begin(), sizes.end(), [](int64_t size) { return size >= 3; }), 10);
  ASSERT_GE(*std::max_element(sizes.begin(), sizes.end()), 20);
  const Volume volume = TakeVolume();
  // Bounds in increasing order, each on a fresh carver over the same volume.
  for (const int64_t bound : {int64_t{2}, int64_t{3}, int64_t{5}, int64_t{20}, int64_t{1} << 40}) {
    int64_t expected = 0;
    for (const int64_t size : sizes) expected += size < bound ? size : 0;
    IncrementalCarver carver(views_, Volume(volume), Options(24, 30.0));
    EXPECT_EQ(carver.RemoveSmallComponents(bound), expected) << bound;
    for (int64_t i = 0; i < grid.num_voxels(); ++i) {
      const bool kept = is_solid[i] && sizes[label[i]] >= bound;
      ASSERT_EQ(carver.volume().IsSolid(i), kept) << bound << " " << i;
    }
  }
}

// Pieces without sparse points: a slab with points on its top, two 3x3x3 cubes above it (one
// holding a point, one none) and a lone voxel with none. At the slab's density (a point on every
// fourth column of two layers, all of them surface: 1 per 8 surface voxels) a cube of 26
// surface voxels should hold about 3.3: the bare cube goes, the one with a point stays, the lone
// voxel (expected 0.13) stays, and so does the slab.
TEST_F(SolidComponents, PiecesWithoutTheSparsePointsTheirSizePredictsAreCarved) {
  const std::vector<CalibratedView>& views = views_;
  const VoxelGrid& grid = grid_;
  const auto set = [&](int x, int y, int z) { Set(x, y, z); };
  const Eigen::Vector3i& n = grid.dimensions();
  std::vector<SurfacePoint> points;
  for (int y = 0; y < n.y(); ++y) {
    for (int x = 0; x < n.x(); ++x) {
      set(x, y, 0), set(x, y, 1);
      // A point on every fourth column's top (the slab's surface is its top, bottom and rim).
      if (x % 2 == 0 && y % 2 == 0) {
        SurfacePoint point;
        point.xyz = grid.Centre(Eigen::Vector3i(x, y, 1));
        points.push_back(point);
      }
    }
  }
  for (int z = 5; z < 8; ++z) {
    for (int y = 4; y < 7; ++y) {
      for (int x = 4; x < 7; ++x) set(x, y, z), set(x + 10, y + 10, z);
    }
  }
  SurfacePoint on_cube;
  on_cube.xyz = grid.Centre(Eigen::Vector3i(15, 15, 8));  // just above the second cube
  points.push_back(on_cube);
  set(20, 4, 6);
  IncrementalCarver carver(views, TakeVolume(), Options(24, 30.0));
  const int64_t solid = carver.volume().num_solid();
  int64_t components = 0;
  double expected = 0.0;
  // Asking for more points than the bare cube should hold keeps it.
  EXPECT_EQ(carver.RemoveUnsupportedComponents(points, 100.0, &components, &expected), 0);
  EXPECT_EQ(components, 0);
  EXPECT_EQ(carver.RemoveUnsupportedComponents(points, 3.0, &components, &expected), 27);
  EXPECT_EQ(components, 1);
  EXPECT_GT(expected, 3.0);
  EXPECT_LT(expected, 10.0);
  EXPECT_EQ(carver.volume().num_solid(), solid - 27);
  EXPECT_FALSE(carver.volume().IsSolid(Eigen::Vector3i(5, 5, 6)));
  EXPECT_TRUE(carver.volume().IsSolid(Eigen::Vector3i(15, 15, 6)));
  EXPECT_TRUE(carver.volume().IsSolid(Eigen::Vector3i(20, 4, 6)));
  // The slab holds the points; without any point at all nothing is judged.
  EXPECT_EQ(carver.RemoveUnsupportedComponents({}, 3.0, &components, &expected), 0);
  // Rays that ended in the carved cube stepped on; the carving carries on from there.
  for (int view = 0; view < static_cast<int>(views.size()); ++view) {
    const RayImage& rays = carver.ray_visibility()->rays(view);
    for (int pixel = 0; pixel < rays.num_pixels(); ++pixel) {
      const int64_t voxel = rays.CurrentVoxel(pixel);
      ASSERT_TRUE(voxel == RayImage::kNoVoxel || carver.volume().IsSolid(voxel)) << pixel;
    }
  }
  while (carver.Step()) {
  }
}

}  // namespace
}  // namespace raycarve
