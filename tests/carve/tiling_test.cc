#include "carve/tiling.h"

#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "carve/level_of_detail.h"
#include "carve/ray_image.h"
#include "tests/carve/carve_fixture.h"

namespace raycarve {
namespace {

using testing::Options;
using testing::Scene;

// The share of `a`'s surface voxels with a solid voxel of `b` within one voxel (26-neighbourhood).
double SurfaceWithinOneVoxel(const Volume& a, const Volume& b) {
  const VoxelGrid& grid = a.grid();
  int64_t near = 0;
  const std::vector<int64_t> surface = a.SurfaceVoxels();
  for (int64_t index : surface) {
    const Eigen::Vector3i voxel = grid.Voxel(index);
    bool found = false;
    for (int dz = -1; dz <= 1 && !found; ++dz) {
      for (int dy = -1; dy <= 1 && !found; ++dy) {
        for (int dx = -1; dx <= 1 && !found; ++dx) {
          found = b.IsSolid(Eigen::Vector3i(voxel + Eigen::Vector3i(dx, dy, dz)));
        }
      }
    }
    near += found;
  }
  return surface.empty() ? 1.0 : static_cast<double>(near) / surface.size();
}

TEST(SplitIntoTiles, CoresPartitionTheGridAndRegionsGrowThemByTheOverlap) {
  const Eigen::Vector3i n(37, 64, 21);
  const std::vector<TileRegion> tiles = SplitIntoTiles(n, Eigen::Vector3i(3, 2, 2), 4);
  ASSERT_EQ(tiles.size(), 12u);
  std::vector<int> owners(static_cast<size_t>(n.x()) * n.y() * n.z(), 0);
  for (const TileRegion& tile : tiles) {
    for (int axis = 0; axis < 3; ++axis) {
      // Cuts are even except at the grid's end; the region is the core and 4 more, in the grid.
      if (tile.core_lo[axis] > 0) {
        EXPECT_EQ(tile.core_lo[axis] % 2, 0);
      }
      if (tile.core_hi[axis] < n[axis]) {
        EXPECT_EQ(tile.core_hi[axis] % 2, 0);
      }
      EXPECT_EQ(tile.lo[axis], std::max(0, tile.core_lo[axis] - 4));
      EXPECT_EQ(tile.hi[axis], std::min(n[axis], tile.core_hi[axis] + 4));
    }
    for (int z = tile.core_lo.z(); z < tile.core_hi.z(); ++z) {
      for (int y = tile.core_lo.y(); y < tile.core_hi.y(); ++y) {
        for (int x = tile.core_lo.x(); x < tile.core_hi.x(); ++x) {
          ++owners[x + n.x() * (y + static_cast<size_t>(n.y()) * z)];
        }
      }
    }
  }
  for (int owner : owners) ASSERT_EQ(owner, 1);
  EXPECT_EQ(tiles[1].index, 1);
  EXPECT_EQ(tiles[1].core_lo.x(), tiles[0].core_hi.x());  // x fastest
}

TEST(CheckTiling, RefusesOneLevelOddOverlapsAndTilesTooSmall) {
  const Eigen::AlignedBox3d box(Eigen::Vector3d::Zero(), Eigen::Vector3d(1.0, 1.0, 0.25));
  CarveOptions options = Options(128, 30.0);
  options.lod_levels = kAutomaticLevels;
  std::string reason;
  EXPECT_TRUE(CheckTiling(box, options, Eigen::Vector3i(2, 2, 2), 8, &reason)) << reason;
  EXPECT_FALSE(CheckTiling(box, options, Eigen::Vector3i(2, 2, 2), 7, &reason));
  EXPECT_NE(reason.find("even"), std::string::npos) << reason;
  EXPECT_FALSE(CheckTiling(box, options, Eigen::Vector3i(2, 2, 16), 8, &reason));  // 32 voxels in z
  EXPECT_NE(reason.find("axis z"), std::string::npos) << reason;
  options.lod_levels = 1;
  EXPECT_FALSE(CheckTiling(box, options, Eigen::Vector3i(2, 2, 2), 8, &reason));
  EXPECT_NE(reason.find("levels of detail"), std::string::npos) << reason;
}

TEST(RefineRegion, GivesTheVoxelsOfThatPartOfTheRefinedVolume) {
  const VoxelGrid coarse_grid(Eigen::AlignedBox3d(Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0.8, 0.5)), 20);
  std::vector<uint64_t> bits((coarse_grid.num_voxels() + 63) / 64, 0);
  for (int64_t i = 0; i < coarse_grid.num_voxels(); i += 7) bits[i >> 6] |= uint64_t{1} << (i & 63);
  const Volume coarse(coarse_grid, bits);
  const VoxelGrid fine(Eigen::AlignedBox3d(Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0.8, 0.5)), 40);
  const Volume whole = RefineVolume(coarse, fine, 1);
  const Eigen::Vector3i lo(6, 2, 4), hi(31, 32, 20);
  const Volume part = RefineRegion(coarse, fine.Region(lo, hi), lo, 1);
  EXPECT_NEAR((part.grid().origin() - (fine.origin() + fine.voxel_size() * lo.cast<double>())).norm(), 0.0, 1e-12);
  for (int z = lo.z(); z < hi.z(); ++z) {
    for (int y = lo.y(); y < hi.y(); ++y) {
      for (int x = lo.x(); x < hi.x(); ++x) {
        const Eigen::Vector3i v(x, y, z);
        ASSERT_EQ(part.IsSolid(Eigen::Vector3i(v - lo)), whole.IsSolid(v)) << v.transpose();
      }
    }
  }
}

TEST(TileViews, APixelWhoseRayMeetsTheOutsideFirstIsNoLongerValid) {
  const SyntheticScene scene = Scene(4, 120, 90);
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  const VoxelGrid grid(scene.object_box, 32);
  const Eigen::AlignedBox3d tile_box = grid.Region(Eigen::Vector3i(12, 12, 0),
                                                   Eigen::Vector3i(20, 20, grid.dimensions().z()))
                                           .Box();
  // The outside: every voxel but the tile's column.
  std::vector<uint64_t> bits((grid.num_voxels() + 63) / 64, 0);
  for (int64_t i = 0; i < grid.num_voxels(); ++i) {
    const Eigen::Vector3i v = grid.Voxel(i);
    if (!(v.x() >= 12 && v.x() < 20 && v.y() >= 12 && v.y() < 20)) bits[i >> 6] |= uint64_t{1} << (i & 63);
  }
  const Volume outside(grid, bits);
  int64_t occluded = 0;
  const std::vector<CalibratedView> tiled = TileViews(views, outside, tile_box, 1, &occluded);
  ASSERT_EQ(tiled.size(), views.size());
  EXPECT_GT(occluded, 0);
  // Brute force, per pixel: the ray enters a solid voxel of the outside before it enters the box.
  int64_t expected = 0, checked = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    const CalibratedView& view = views[v];
    const RayImage rays(grid, view.WorldFromPixel(), view.centre, view.width, view.height);
    for (int pixel = 0; pixel < view.width * view.height; pixel += 5) {
      const Eigen::Vector3d d = rays.Direction(pixel);
      double near = 0.0, far = 0.0;
      bool hidden = false;
      if (ClipRayToBox(view.centre, d, tile_box, &near, &far)) {
        for (int64_t i = 0; i < grid.num_voxels() && !hidden; ++i) {
          if (!outside.IsSolid(i)) continue;
          double enter = 0.0;
          if (testing::RayEntersVoxel(grid, grid.Voxel(i), view.centre, d, &enter)) {
            hidden = enter < near - 1e-9;
          }
        }
      }
      const bool was_valid = view.valid.empty() || view.valid.data[pixel] != 0;
      if (!was_valid) continue;
      ++checked;
      expected += hidden;
      ASSERT_EQ(tiled[v].valid.data[pixel] == 0, hidden) << "view " << v << " pixel " << pixel;
    }
    EXPECT_EQ(tiled[v].image.data, view.image.data);  // the photo is shared, not copied
  }
  EXPECT_GT(expected, 0);
  EXPECT_LT(expected, checked);
}

TEST(BoxInView, IsTrueForEveryBoxAPointOfWhichProjectsIntoThePhoto) {
  const SyntheticScene scene = Scene(4, 120, 90);
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  const Eigen::Vector3d centre = scene.object_box.center();
  const double size = scene.object_box.sizes().maxCoeff();
  int seen = 0, unseen = 0;
  for (int b = 0; b < 400; ++b) {
    // Boxes of assorted sizes around the scene, some behind or beside the cameras.
    const Eigen::Vector3d at = centre + 3.0 * size * Eigen::Vector3d(std::sin(b * 1.3), std::cos(b * 0.7),
                                                                       0.5 * std::sin(b * 2.1));
    const Eigen::AlignedBox3d box(at, at + Eigen::Vector3d::Constant(0.05 * size * (1 + b % 5)));
    for (const CalibratedView& view : views) {
      bool projects = false;
      for (int i = 0; i <= 8 && !projects; ++i) {
        for (int j = 0; j <= 8 && !projects; ++j) {
          for (int k = 0; k <= 8 && !projects; ++k) {
            const Eigen::Vector3d p = box.min() + box.sizes().cwiseProduct(Eigen::Vector3d(i, j, k) / 8.0);
            const Eigen::Vector2d pixel = view.Project(p);
            projects = view.Depth(p) > 0.0 && pixel.x() >= 0 && pixel.y() >= 0 &&
                       pixel.x() <= view.width && pixel.y() <= view.height;
          }
        }
      }
      const bool in_view = BoxInView(view, box);
      if (projects) {
        EXPECT_TRUE(in_view) << "box " << b;
      }
      seen += in_view;
      unseen += !in_view;
    }
  }
  // Both answers occur: the test is not passed by answering true.
  EXPECT_GT(seen, 100);
  EXPECT_GT(unseen, 100);
  // A box behind a camera is not in its view.
  const CalibratedView& view = views[0];
  const Eigen::Vector3d behind = view.centre - 2.0 * (view.cam_from_world.rotation.conjugate() *
                                                      Eigen::Vector3d::UnitZ());
  EXPECT_FALSE(BoxInView(view, Eigen::AlignedBox3d(behind, behind + Eigen::Vector3d::Constant(0.1))));
}

// The three steps against one carve, on a generated scene at 64 voxels in two levels.
TEST(TiledCarve, JoinsToTheSingleCarveWithinOneVoxel) {
  const SyntheticScene scene = Scene(8, 240, 180);
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  CarveOptions options = Options(64, 30.0);
  options.lod_levels = 2;
  options.surface_points = testing::SceneSurfacePoints(scene);
  options.protect_surface_points = true;
  options.free_space_margin_voxels = 2.0;
  const CarveResult single = CarveVolume(views, scene.object_box, options);

  std::string reason;
  ASSERT_TRUE(CheckTiling(scene.object_box, options, Eigen::Vector3i(2, 2, 2), 4, &reason)) << reason;
  const CoarseCarve coarse = CarveCoarseLevels(views, scene.object_box, options);
  EXPECT_EQ(coarse.volume.grid().dimensions(), VoxelGrid(scene.object_box, 32).dimensions());
  EXPECT_DOUBLE_EQ(coarse.final_threshold, 30.0);
  ASSERT_EQ(coarse.statistics.levels.size(), 1u);
  EXPECT_EQ(coarse.statistics.levels[0].final_solid, single.statistics.levels[0].final_solid);

  const VoxelGrid grid(scene.object_box, 64);
  const std::vector<TileRegion> tiles = SplitIntoTiles(grid.dimensions(), Eigen::Vector3i(2, 2, 2), 4);
  std::vector<std::vector<uint64_t>> cores;
  int64_t tile_evaluated = 0;
  for (const TileRegion& tile : tiles) {
    const TileCarve carved = CarveTile(views, scene.object_box, options, coarse, tile);
    EXPECT_EQ(carved.volume.grid().dimensions(), tile.hi - tile.lo);
    tile_evaluated += carved.statistics.evaluated;
    cores.push_back(CoreBits(carved.volume, tile));
    // A tile carved again gives the same part.
    if (tile.index == 3) {
      EXPECT_EQ(CoreBits(CarveTile(views, scene.object_box, options, coarse, tile).volume, tile),
                cores.back());
    }
  }
  const Volume joined = JoinTileCores(grid, tiles, cores);
  const CarveResult tiled = FinishTiledCarve(views, scene.object_box, options, joined,
                                             coarse.volume, coarse.final_threshold,
                                             coarse.final_pattern_threshold);
  EXPECT_EQ(tiled.volume.grid().dimensions(), grid.dimensions());
  EXPECT_EQ(tiled.surface.size(), static_cast<size_t>(tiled.volume.num_surface()));
  const VolumeAgreement agreement = CompareVolumes(single.volume, tiled.volume);
  const double tiled_near = SurfaceWithinOneVoxel(tiled.volume, single.volume);
  const double single_near = SurfaceWithinOneVoxel(single.volume, tiled.volume);
  std::printf("tiled against single: IoU %.4f, %lld voxels differ of %lld solid; surface within one "
              "voxel of the other's solid: tiled %.4f, single %.4f; evaluations: tiles %lld, "
              "finish %lld, single final level %lld\n",
              agreement.iou(), static_cast<long long>(agreement.differing()),
              static_cast<long long>(single.volume.num_solid()), tiled_near, single_near,
              static_cast<long long>(tile_evaluated),
              static_cast<long long>(tiled.statistics.evaluated),
              static_cast<long long>(single.statistics.levels.back().evaluated));
  EXPECT_GT(agreement.iou(), 0.97);
  EXPECT_GT(tiled_near, 0.99);
  EXPECT_GT(single_near, 0.99);
  // The finish carves on from the tiles, which did most of the final level's work.
  EXPECT_LT(tiled.statistics.evaluated, tile_evaluated);
}

}  // namespace
}  // namespace raycarve
