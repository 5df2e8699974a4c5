#include "export/volume_renderer.h"

#include <cstdio>
#include <random>

#include <gtest/gtest.h>

namespace raycarve {
namespace exporter {
namespace {

// A 60x50 pinhole view at `centre` looking at `target`, f = 70.
CalibratedView LookAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target) {
  CalibratedView view;
  view.width = 60;
  view.height = 50;
  view.K << 70, 0, 30, 0, 70, 25, 0, 0, 1;
  const Eigen::Vector3d forward = (target - centre).normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d(0.1, 0.2, 1)).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d cam_from_world;
  cam_from_world.row(0) = right.transpose();
  cam_from_world.row(1) = down.transpose();
  cam_from_world.row(2) = forward.transpose();
  view.cam_from_world.rotation = Eigen::Quaterniond(cam_from_world);
  view.cam_from_world.translation = -cam_from_world * centre;
  view.centre = centre;
  view.P = view.K * view.cam_from_world.ToMatrix();
  return view;
}

// Brute force: the solid voxel whose cube the ray through the pixel centre enters first, or -1.
int64_t FirstSolidByBruteForce(const Volume& volume, const CalibratedView& view, int pixel) {
  const VoxelGrid& grid = volume.grid();
  const Eigen::Vector3d direction =
      view.WorldFromPixel() *
      Eigen::Vector3d(pixel % view.width + 0.5, pixel / view.width + 0.5, 1.0);
  int64_t best = -1;
  double best_t = 1e300;
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    if (!volume.IsSolid(index)) continue;
    const Eigen::Vector3d lo = grid.Corner(grid.Voxel(index), 0), hi = grid.Corner(grid.Voxel(index), 7);
    double t0 = 0.0, t1 = 1e300;
    for (int axis = 0; axis < 3; ++axis) {
      double a = (lo[axis] - view.centre[axis]) / direction[axis];
      double b = (hi[axis] - view.centre[axis]) / direction[axis];
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
    }
    if (t1 - t0 > 1e-9 && t0 < best_t) {
      best_t = t0;
      best = index;
    }
  }
  return best;
}

TEST(RenderVolume, EveryPixelShowsTheColourOfTheFirstSolidVoxelOnItsRay) {
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d(-1, -0.8, -0.6), Eigen::Vector3d(1, 0.8, 0.6)), 14);
  // Two balls and a slab, so that rays hit, pass between and are occluded.
  Volume volume(grid);
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    const Eigen::Vector3d p = grid.Centre(grid.Voxel(index));
    const bool ball_a = (p - Eigen::Vector3d(-0.4, 0.1, 0.1)).norm() < 0.45;
    const bool ball_b = (p - Eigen::Vector3d(0.5, -0.2, 0.0)).norm() < 0.3;
    const bool slab = p.z() < -0.4;
    if (!ball_a && !ball_b && !slab) volume.Carve(index, nullptr);
  }
  // Each surface voxel's colour encodes its index; every fifth has none (no photo saw it).
  std::vector<ColouredVoxel> surface;
  for (int64_t index : volume.SurfaceVoxels()) {
    ColouredVoxel voxel;
    voxel.index = index;
    voxel.num_pixels = index % 5 == 0 ? 0 : 3;
    voxel.colour = Eigen::Vector3f(index % 251, index / 251 % 251, 200);
    surface.push_back(voxel);
  }
  std::sort(surface.begin(), surface.end(),
            [](const ColouredVoxel& a, const ColouredVoxel& b) { return a.index < b.index; });
  std::mt19937_64 random(3);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  int hits = 0, misses = 0;
  for (int trial = 0; trial < 4; ++trial) {
    Eigen::Vector3d centre(uniform(random), uniform(random), 0.3 + std::abs(uniform(random)));
    centre = 3.0 * centre.normalized();
    const CalibratedView view = LookAt(centre, Eigen::Vector3d(0.05 * trial, 0.0, -0.1));
    const VolumeRendering rendering = RenderVolume(volume, surface, view);
    int uncoloured = 0;
    for (int pixel = 0; pixel < view.width * view.height; ++pixel) {
      const int row = pixel / view.width, col = pixel % view.width;
      const int64_t expected = FirstSolidByBruteForce(volume, view, pixel);
      ASSERT_EQ(rendering.silhouette.at<uint8_t>(row, col) != 0, expected >= 0)
          << "trial " << trial << " pixel " << pixel;
      if (expected < 0) {
        ++misses;
        EXPECT_EQ(rendering.image.at<cv::Vec3b>(row, col), cv::Vec3b(0, 0, 0));
        continue;
      }
      ++hits;
      ASSERT_TRUE(volume.IsSurface(expected));
      EXPECT_NEAR(rendering.depth.at<float>(row, col),
                  view.Depth(grid.Centre(grid.Voxel(expected))), 1e-4);
      if (expected % 5 == 0) {
        ++uncoloured;
        continue;  // a neighbour's colour
      }
      const cv::Vec3b want(expected % 251, expected / 251 % 251, 200);
      ASSERT_EQ(rendering.image.at<cv::Vec3b>(row, col), want) << "pixel " << pixel;
    }
    EXPECT_EQ(rendering.uncoloured_pixels, uncoloured);
  }
  EXPECT_GT(hits, 1000);
  EXPECT_GT(misses, 1000);
}

TEST(RenderVolume, ASolidBoxCoversItsWholeOutlineWithoutGaps) {
  // Splatting a cloud of voxel centres leaves gaps between splats seen obliquely; the volume
  // rendering covers every pixel whose ray meets the box.
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 1)), 10);
  const Volume volume(grid);
  std::vector<ColouredVoxel> surface;
  for (int64_t index : volume.SurfaceVoxels()) {
    ColouredVoxel voxel;
    voxel.index = index;
    voxel.num_pixels = 1;
    voxel.colour = Eigen::Vector3f(90, 90, 90);
    surface.push_back(voxel);
  }
  std::sort(surface.begin(), surface.end(),
            [](const ColouredVoxel& a, const ColouredVoxel& b) { return a.index < b.index; });
  const CalibratedView view = LookAt(Eigen::Vector3d(3.1, 2.3, 1.9), Eigen::Vector3d::Zero());
  const VolumeRendering rendering = RenderVolume(volume, surface, view);
  int inside = 0;
  for (int pixel = 0; pixel < view.width * view.height; ++pixel) {
    const bool meets = FirstSolidByBruteForce(volume, view, pixel) >= 0;
    inside += meets;
    ASSERT_EQ(rendering.silhouette.at<uint8_t>(pixel / view.width, pixel % view.width) != 0, meets);
  }
  EXPECT_GT(inside, 500);
  EXPECT_EQ(rendering.uncoloured_pixels, 0);
  EXPECT_EQ(cv::countNonZero(rendering.silhouette), inside);
  // The same surface splatted as a cloud of voxel centres misses part of it.
  std::vector<ColouredPoint> points;
  for (const ColouredVoxel& voxel : surface) {
    ColouredPoint point;
    point.xyz = grid.Centre(grid.Voxel(voxel.index)).cast<float>();
    points.push_back(point);
  }
  const int splatted = cv::countNonZero(RenderPoints(points, view, grid.voxel_size()).silhouette);
  std::printf("pixels covered: volume %d, splats %d\n", inside, splatted);
  EXPECT_LT(splatted, inside);
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
