#include "carve/footprint.h"

#include <gtest/gtest.h>

namespace raycarve {
namespace {

// A camera at the origin looking down +z with f = 100 and principal point (50, 50): a point
// (x, y, z) projects to (50 + 100 x / z, 50 + 100 y / z).
Eigen::Matrix<double, 3, 4> Camera() {
  Eigen::Matrix<double, 3, 4> P;
  P << 100, 0, 50, 0, 0, 100, 50, 0, 0, 0, 1, 0;
  return P;
}

TEST(Footprint, IsTheBoundingBoxOfTheProjectedCornersInPixelCentres) {
  // Grid of 0.1 voxels from (0, 0, 10): voxel (0, 0, 0) spans x, y in [0, 0.1], z in [10, 10.1].
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, 10), Eigen::Vector3d(1, 1, 11)), 10);
  const Footprint footprint = ComputeFootprint(Camera(), 100, 100, grid, Eigen::Vector3i(0, 0, 0));
  // x from 50 + 100 * 0 / z = 50 to 50 + 100 * 0.1 / 10 = 51: pixel centres 50.5 only.
  EXPECT_EQ(footprint.col_min, 50);
  EXPECT_EQ(footprint.col_max, 50);
  EXPECT_EQ(footprint.row_min, 50);
  EXPECT_EQ(footprint.row_max, 50);
  EXPECT_EQ(footprint.area(), 1);
}

TEST(Footprint, IncludesPixelCentresWithinAHundredthOfAPixelOfItsEdge) {
  // The voxel's smallest projected x is 50 + 100 * shift / 10.1 (its near-left edge at the far
  // depth 10.1). With that at 50.505, pixel centre 50.5 lies 0.005 px outside the exact box.
  const double shift = 0.00505 * 10.1;
  const VoxelGrid grid(
      Eigen::AlignedBox3d(Eigen::Vector3d(shift, 0, 10), Eigen::Vector3d(1 + shift, 1, 11)), 10);
  const Footprint near = ComputeFootprint(Camera(), 100, 100, grid, Eigen::Vector3i(0, 0, 0));
  EXPECT_EQ(near.col_min, 50);  // 0.005 px outside: kept (rays are stepped with float precision)
  const double far_shift = 0.0055 * 10.1;  // 0.05 px outside: left out
  const VoxelGrid far_grid(
      Eigen::AlignedBox3d(Eigen::Vector3d(far_shift, 0, 10), Eigen::Vector3d(1 + far_shift, 1, 11)), 10);
  EXPECT_EQ(ComputeFootprint(Camera(), 100, 100, far_grid, Eigen::Vector3i(0, 0, 0)).col_min, 51);
}

TEST(Footprint, IsClippedToTheImageAndEmptyBehindTheCamera) {
  // One voxel straddling the optical axis, far wider than the view.
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d(-10, -10, 1), Eigen::Vector3d(10, 10, 21)), 1);
  const Footprint big = ComputeFootprint(Camera(), 100, 100, grid, Eigen::Vector3i(0, 0, 0));
  EXPECT_EQ(big.col_min, 0);
  EXPECT_EQ(big.row_min, 0);
  EXPECT_EQ(big.col_max, 99);
  EXPECT_EQ(big.row_max, 99);
  const VoxelGrid behind(Eigen::AlignedBox3d(Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(1, 1, 0.5)), 2);
  EXPECT_TRUE(ComputeFootprint(Camera(), 100, 100, behind, Eigen::Vector3i(0, 0, 0)).empty());
  const VoxelGrid outside(Eigen::AlignedBox3d(Eigen::Vector3d(50, 0, 10), Eigen::Vector3d(51, 1, 11)), 2);
  EXPECT_TRUE(ComputeFootprint(Camera(), 100, 100, outside, Eigen::Vector3i(0, 0, 0)).empty());
}

TEST(Footprint, AVoxelAlmostOnTheCamerasPlaneCoversThePhotoItStraddles) {
  // Corners at depth 1e-9: projected 1e11 pixels from the principal point, beyond any int. The
  // voxel straddles the optical axis, so it covers the whole photo; one beside the axis covers
  // none of it.
  const VoxelGrid grid(
      Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, 1e-9), Eigen::Vector3d(1, 1, 2 + 1e-9)), 1);
  const Footprint straddling = ComputeFootprint(Camera(), 100, 100, grid, Eigen::Vector3i(0, 0, 0));
  EXPECT_EQ(straddling.col_min, 0);
  EXPECT_EQ(straddling.col_max, 99);
  EXPECT_EQ(straddling.row_min, 0);
  EXPECT_EQ(straddling.row_max, 99);
  const VoxelGrid beside(
      Eigen::AlignedBox3d(Eigen::Vector3d(1, 1, 1e-9), Eigen::Vector3d(3, 3, 2 + 1e-9)), 1);
  EXPECT_TRUE(ComputeFootprint(Camera(), 100, 100, beside, Eigen::Vector3i(0, 0, 0)).empty());
}

}  // namespace
}  // namespace raycarve
