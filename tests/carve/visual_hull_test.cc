#include "carve/visual_hull.h"

#include <cmath>

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

// Marks as object, in every view's mask, the projection of a cube of side `side` around
// `centre` (a sky unlike the backdrop, which an automatic mask calls object).
void PaintSpuriousObject(const Eigen::Vector3d& centre, double side,
                         std::vector<CalibratedView>* views) {
  for (CalibratedView& view : *views) {
    Eigen::AlignedBox2d rect;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d corner =
          centre + 0.5 * side * Eigen::Vector3d(c & 1 ? 1 : -1, c & 2 ? 1 : -1, c & 4 ? 1 : -1);
      if (view.Depth(corner) > 0.0) rect.extend(view.Project(corner));
    }
    if (rect.isEmpty()) continue;
    const cv::Rect pixels = cv::Rect(cv::Point(static_cast<int>(rect.min().x()),
                                               static_cast<int>(rect.min().y())),
                                     cv::Point(static_cast<int>(rect.max().x()) + 1,
                                               static_cast<int>(rect.max().y()) + 1)) &
                            cv::Rect(0, 0, view.width, view.height);
    if (pixels.area() > 0) view.mask(pixels).setTo(255);
  }
}

TEST(VisualHullBox, HoldsTheObjectAndLeavesOutAPieceWithoutSparsePoints) {
  const SyntheticScene scene = BackdropScene();
  std::vector<CalibratedView> views = testing::SceneViews(scene, /*with_masks=*/true);
  // A box three times as wide as the objects (the sparse points of a field around them).
  const Eigen::Vector3d size = scene.object_box.sizes();
  const Eigen::AlignedBox3d box(scene.object_box.min() - size, scene.object_box.max() + size);
  // Something the masks call object above and beside the objects, where no sparse point is.
  const Eigen::Vector3d spurious =
      scene.object_box.max() + Eigen::Vector3d(0.6 * size.x(), 0.6 * size.y(), 0.3 * size.z());
  PaintSpuriousObject(spurious, 0.1 * size.maxCoeff(), &views);
  // The sparse points: samples of the true surface that two views see.
  const std::vector<Eigen::Vector3d> truth = SampleTrueSurface(scene, 20000, 3, 2);
  ASSERT_GT(truth.size(), 5000u);
  const std::vector<Eigen::Vector3d> points(truth.begin(), truth.begin() + 300);

  // Two stray points there (wrong matches) do not make it an object.
  std::vector<Eigen::Vector3d> with_strays = points;
  with_strays.push_back(spurious);
  with_strays.push_back(spurious + Eigen::Vector3d::Constant(0.01 * size.maxCoeff()));

  const HullBox hull = VisualHullBox(views, with_strays, box, 64, 2, 2);
  EXPECT_EQ(hull.pieces, 1);
  EXPECT_GE(hull.pieces_left, 1);
  EXPECT_EQ(hull.points, 300);
  int outside = 0;
  for (const Eigen::Vector3d& point : truth) outside += !hull.box.contains(point);
  EXPECT_EQ(outside, 0) << "of " << truth.size() << " true surface points";
  EXPECT_FALSE(hull.box.contains(spurious));
  // Narrow across: eight views leave a hull wider than the objects, but well inside the box
  // three times their size. (Upwards and downwards it is not: photos from above see the ground
  // square, which the masks call object, behind and under whatever lies over it.)
  EXPECT_TRUE(hull.box.contains(scene.object_box));
  for (int axis = 0; axis < 2; ++axis) {
    EXPECT_LT(hull.box.sizes()[axis], 0.6 * box.sizes()[axis]) << "axis " << axis;
  }

  // A second object there, its surface as densely pointed as the first's: it counts.
  std::vector<Eigen::Vector3d> second = points;
  const double side = 0.1 * size.maxCoeff();
  for (int i = 0; i < 30; ++i) {
    second.push_back(spurious + 0.4 * side * Eigen::Vector3d(std::cos(i), std::sin(i), (i % 5 - 2) / 2.0));
  }
  const HullBox both = VisualHullBox(views, second, box, 64, 2, 2);
  EXPECT_EQ(both.pieces, 2);
  EXPECT_TRUE(both.box.contains(spurious));
  EXPECT_TRUE(both.box.contains(hull.box));

  // Without sparse points every piece counts: the spurious one too.
  const HullBox every = VisualHullBox(views, {}, box, 64, 2, 2);
  EXPECT_GE(every.pieces, 2);
  EXPECT_TRUE(every.box.contains(spurious));
  EXPECT_TRUE(every.box.contains(hull.box));

  // Without masks: the box as given.
  const HullBox unmasked = VisualHullBox(testing::SceneViews(scene), points, box, 64, 2, 2);
  EXPECT_TRUE(unmasked.box.isApprox(box));
  EXPECT_EQ(unmasked.voxels, 0);
}

}  // namespace
}  // namespace raycarve
