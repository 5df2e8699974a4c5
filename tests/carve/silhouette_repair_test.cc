#include "carve/silhouette_repair.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "carve/ray_image.h"
#include "carve/visual_hull.h"
#include "tests/carve/carve_fixture.h"

namespace raycarve {
namespace {

std::unique_ptr<RayImage> RaysOf(const CalibratedView& view, const Volume& volume) {
  const Eigen::Matrix3d world_from_pixel = view.WorldFromPixel();
  auto rays = std::make_unique<RayImage>(volume.grid(), world_from_pixel, view.centre, view.width,
                                         view.height, view.valid & view.mask);
  rays->Initialise(volume);
  return rays;
}

class SilhouetteRepair : public ::testing::Test {
 protected:
  void SetUp() override {
    // The generated scene on a uniform backdrop with its exact masks (the objects and the ground
    // square are the object).
    scene_ = std::make_unique<SyntheticScene>(
        GenerateSyntheticScene(testing::SceneOptions(6, 160, 120, /*uniform_backdrop=*/true)));
    views_ = testing::SceneViews(*scene_, /*with_masks=*/true);
    hull_ = std::make_unique<Volume>(VoxelGrid(scene_->object_box, 48));
    CarveVisualHull(views_, hull_.get());
  }
  std::unique_ptr<SyntheticScene> scene_;
  std::vector<CalibratedView> views_;
  std::unique_ptr<Volume> hull_;
};

TEST_F(SilhouetteRepair, RestoresNothingWhereCarvingTookNothing) {
  Volume volume = *hull_;
  const SilhouetteRepairSummary summary = RepairSilhouettes(views_, &volume);
  EXPECT_EQ(summary.views, 6);
  EXPECT_GT(summary.object_pixels, 10000);
  EXPECT_EQ(summary.lost_pixels, 0);
  EXPECT_EQ(summary.restored_voxels, 0);
  EXPECT_EQ(volume.solid_bits(), hull_->solid_bits());

  // Views without masks are not repaired.
  const std::vector<CalibratedView> unmasked = testing::SceneViews(*scene_);
  Volume empty(hull_->grid(), std::vector<uint64_t>(hull_->solid_bits().size(), 0));
  const SilhouetteRepairSummary none = RepairSilhouettes(unmasked, &empty);
  EXPECT_EQ(none.views, 0);
  EXPECT_EQ(empty.num_solid(), 0);
}

TEST_F(SilhouetteRepair, ClosesATunnelWithAMembraneNearTheSurroundingSurface) {
  // A tunnel drilled through the hull along the first view's ray through the grid's centre:
  // its pixels there lose the model, as after a carve that ran away.
  const CalibratedView& view = views_[0];
  const VoxelGrid& grid = hull_->grid();
  const Eigen::Vector3d axis = (grid.Box().center() - view.centre).normalized();
  const double radius = 4.0 * grid.voxel_size();
  std::vector<uint64_t> solid = hull_->solid_bits();
  std::vector<int64_t> drilled;
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    if (!hull_->IsSolid(index)) continue;
    const Eigen::Vector3d offset = grid.Centre(grid.Voxel(index)) - view.centre;
    if ((offset - offset.dot(axis) * axis).norm() > radius) continue;
    solid[index >> 6] &= ~(uint64_t{1} << (index & 63));
    drilled.push_back(index);
  }
  ASSERT_GT(drilled.size(), 20u);
  const Volume before(grid, solid);
  // The depth of the model around the tunnel in the first view (rays meeting it, within 5.5 to 9
  // voxel widths of the tunnel's axis on the image).
  const std::unique_ptr<RayImage> drilled_rays = RaysOf(view, before);
  const Eigen::Vector3d centre_pixel = view.K * (view.cam_from_world * grid.Box().center());
  const double voxel_pixels = view.K(0, 0) * grid.voxel_size() / view.Depth(grid.Box().center());
  std::vector<double> around;
  double nearest = 1e300, farthest = 0.0;  // the model's depths within 9 voxel widths
  int lost_in_view = 0;
  for (int p = 0; p < drilled_rays->num_pixels(); ++p) {
    const double dx = p % view.width + 0.5 - centre_pixel.x() / centre_pixel.z();
    const double dy = p / view.width + 0.5 - centre_pixel.y() / centre_pixel.z();
    const double distance = std::hypot(dx, dy) / voxel_pixels;
    const int64_t voxel = drilled_rays->CurrentVoxel(p);
    if (voxel == RayImage::kNoVoxel) {
      lost_in_view += distance < 1.0;
      continue;
    }
    const double depth = view.Depth(grid.Centre(grid.Voxel(voxel)));
    if (distance < 9.0) {
      nearest = std::min(nearest, depth);
      farthest = std::max(farthest, depth);
    }
    if (distance > 5.5) around.push_back(depth);
  }
  ASSERT_GT(lost_in_view, 0) << "the tunnel must go through";
  ASSERT_GT(around.size(), 20u);
  std::sort(around.begin(), around.end());
  const double surrounding = around[around.size() / 2];

  // The first view alone: its membrane spans the hole near the surface around it (its depth
  // taken from the rays around the hole, the tunnel's walls among them), not at the back of the
  // hull, which the tunnel runs through to:
  double hull_back = 0.0;
  for (int64_t index : drilled) {
    hull_back = std::max(hull_back, view.Depth(grid.Centre(grid.Voxel(index))));
  }
  ASSERT_GT(hull_back, surrounding + 5.0 * grid.voxel_size());
  Volume first = before;
  const SilhouetteRepairSummary first_summary = RepairSilhouettes({view}, &first);
  EXPECT_GT(first_summary.restored_voxels, 0);
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    if (first.IsSolid(index) && !before.IsSolid(index)) {
      const double depth = view.Depth(grid.Centre(grid.Voxel(index)));
      EXPECT_GE(depth, nearest - grid.voxel_size());
      EXPECT_LT(std::abs(depth - surrounding), std::abs(depth - hull_back)) << depth;
    }
  }

  // Every view in turn.
  Volume volume = before;
  const SilhouetteRepairSummary summary = RepairSilhouettes(views_, &volume);
  std::cout << "drilled " << drilled.size() << " voxels, " << lost_in_view
            << " pixels of the first view lost near the axis; " << summary.Summary()
            << "; the model around it from depth " << nearest << " (median " << surrounding
            << ") to " << farthest << ", the hull to " << hull_back << "\n";
  EXPECT_GT(summary.lost_pixels, 0);
  EXPECT_GT(summary.restored_voxels, 0);
  EXPECT_EQ(volume.num_solid(), before.num_solid() + summary.restored_voxels);
  // The rays split among threads: the same repair.
  Volume threaded = before;
  const SilhouetteRepairSummary threaded_summary = RepairSilhouettes(views_, &threaded, 3);
  EXPECT_EQ(threaded.solid_bits(), volume.solid_bits());
  EXPECT_EQ(threaded_summary.lost_pixels, summary.lost_pixels);
  // Only added, only where the tunnel took the hull.
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    if (before.IsSolid(index)) {
      EXPECT_TRUE(volume.IsSolid(index));
    } else if (volume.IsSolid(index)) {
      EXPECT_TRUE(std::binary_search(drilled.begin(), drilled.end(), index)) << index;
    }
  }
  // No restored voxel meets a solid voxel only along an edge where a hull voxel could join them:
  // such steps leak in other photos and part the mesh.
  EXPECT_GT(summary.bridging_voxels, 0);
  EXPECT_LT(summary.bridging_voxels, summary.restored_voxels);
  // The twelve edge neighbours: two coordinates off by one, the third the same.
  std::vector<Eigen::Vector3i> edge_offsets;
  for (int dx = -1; dx <= 1; ++dx) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dz = -1; dz <= 1; ++dz) {
        if (std::abs(dx) + std::abs(dy) + std::abs(dz) == 2) edge_offsets.emplace_back(dx, dy, dz);
      }
    }
  }
  ASSERT_EQ(edge_offsets.size(), 12u);
  int edge_only = 0;
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    if (before.IsSolid(index) || !volume.IsSolid(index)) continue;
    const Eigen::Vector3i cell = grid.Voxel(index);
    for (const Eigen::Vector3i& offset : edge_offsets) {
      const Eigen::Vector3i diagonal = cell + offset;
      if (!grid.Contains(diagonal) || !volume.IsSolid(grid.Index(diagonal))) continue;
      // The two face neighbours shared by the voxel and its edge neighbour: one step of the
      // offset each.
      Eigen::Vector3i first = cell, second = cell;
      int moved = 0;
      for (int axis = 0; axis < 3; ++axis) {
        if (offset[axis] == 0) continue;
        (moved++ == 0 ? first : second)[axis] += offset[axis];
      }
      const int64_t a = grid.Index(first), b = grid.Index(second);
      edge_only += !volume.IsSolid(a) && !volume.IsSolid(b) && (hull_->IsSolid(a) || hull_->IsSolid(b));
    }
  }
  EXPECT_EQ(edge_only, 0);
  // Every pixel of every view inside the silhouette's rim whose ray met the hull meets the model.
  for (const CalibratedView& v : views_) {
    const std::unique_ptr<RayImage> hull_rays = RaysOf(v, *hull_);
    const std::unique_ptr<RayImage> rays = RaysOf(v, volume);
    const double pixels = v.K(0, 0) * grid.voxel_size() / v.Depth(grid.Box().center());
    const int rim = static_cast<int>(std::ceil(1.5 * pixels));
    cv::Mat inside;
    cv::erode(v.mask, inside,
              cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * rim + 1, 2 * rim + 1)));
    int still_lost = 0;
    for (int p = 0; p < rays->num_pixels(); ++p) {
      still_lost += inside.data[p] != 0 && hull_rays->CurrentVoxel(p) != RayImage::kNoVoxel &&
                    rays->CurrentVoxel(p) == RayImage::kNoVoxel;
    }
    EXPECT_EQ(still_lost, 0) << v.name;
  }
}

}  // namespace
}  // namespace raycarve
