#include "export/mesh_renderer.h"

#include <cmath>

#include <gtest/gtest.h>

#include "export/holdout_score.h"
#include "tests/test_support.h"

namespace raycarve {
namespace exporter {
namespace {

// A 40x30 pinhole view at the origin looking down +z (x right, y down), f = 50.
CalibratedView Straight() { return testing::PinholeViewAtOrigin(40, 30, 50); }

// The world point at depth z that projects to COLMAP pixel (x, y).
Eigen::Vector3f Unproject(const CalibratedView& view, double x, double y, double z) {
  return Eigen::Vector3f(static_cast<float>((x - view.K(0, 2)) / view.K(0, 0) * z),
                         static_cast<float>((y - view.K(1, 2)) / view.K(1, 1) * z),
                         static_cast<float>(z));
}

TEST(RenderMesh, ARectangleCoversExactlyThePixelCentresInsideItAtItsDepth) {
  const CalibratedView view = Straight();
  // Pixel corners 10..30 across, 5..20 down, at depth 4: centres 10.5..29.5, 5.5..19.5 inside.
  TriangleMesh mesh;
  mesh.vertices = {Unproject(view, 10, 5, 4), Unproject(view, 30, 5, 4), Unproject(view, 30, 20, 4),
                   Unproject(view, 10, 20, 4)};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  const Rendering rendering = RenderMesh(mesh, view);
  for (int row = 0; row < view.height; ++row) {
    for (int col = 0; col < view.width; ++col) {
      const bool inside = col >= 10 && col < 30 && row >= 5 && row < 20;
      ASSERT_EQ(rendering.silhouette.at<uint8_t>(row, col) != 0, inside) << col << "," << row;
      if (inside) {
        EXPECT_NEAR(rendering.depth.at<float>(row, col), 4.0f, 1e-5f);
        EXPECT_EQ(rendering.image.at<cv::Vec3b>(row, col), cv::Vec3b(128, 128, 128));
      } else {
        EXPECT_TRUE(std::isinf(rendering.depth.at<float>(row, col)));
      }
    }
  }
}

TEST(MeasureSparseDepth, PointsAtTheDrawnDepthBehindItInFrontOfItAndOutside) {
  const CalibratedView view = Straight();
  TriangleMesh mesh;  // pixels 10..30 across, 5..20 down, at depth 4
  mesh.vertices = {Unproject(view, 10, 5, 4), Unproject(view, 30, 5, 4), Unproject(view, 30, 20, 4),
                   Unproject(view, 10, 20, 4)};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  const Rendering rendering = RenderMesh(mesh, view);
  const auto at = [&](double x, double y, double z) -> Eigen::Vector3d {
    return Unproject(view, x, y, z).cast<double>();
  };
  const std::vector<Eigen::Vector3d> points = {
      at(15.5, 10.5, 4.1),   // on the surface, within the tolerance: at depth
      at(20.5, 12.5, 3.8),   // likewise, a little in front
      at(25.5, 15.5, 6.0),   // behind it: hidden by the surface
      at(12.5, 7.5, 2.0),    // in front of it: the model lies behind the point
      at(35.5, 25.5, 4.0),   // where nothing is drawn
      at(45.5, 10.5, 4.0),   // outside the frame: not counted
      Eigen::Vector3d(0, 0, -3)};  // behind the camera: not counted
  std::vector<SparsePointDepth> records;
  const SparseDepthAgreement agreement = MeasureSparseDepth(rendering, view, points, 0.5, &records);
  EXPECT_EQ(agreement.points, 5);
  // Each point counted, in the order given, with its verdict and both depths.
  ASSERT_EQ(records.size(), 5u);
  const SparseDepthVerdict expected[] = {SparseDepthVerdict::kAtDepth, SparseDepthVerdict::kAtDepth,
                                         SparseDepthVerdict::kHidden, SparseDepthVerdict::kBehind,
                                         SparseDepthVerdict::kUndrawn};
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(records[i].verdict, expected[i]) << i;
    EXPECT_TRUE(records[i].point.isApprox(points[i])) << i;
    EXPECT_NEAR(records[i].depth, view.Depth(points[i]), 1e-9) << i;
  }
  EXPECT_NEAR(records[2].drawn_depth, 4.0, 1e-3);
  EXPECT_TRUE(std::isinf(records[4].drawn_depth));
  EXPECT_STREQ(SparseDepthVerdictName(records[2].verdict), "hidden");
  EXPECT_EQ(agreement.at_depth, 2);
  EXPECT_EQ(agreement.hidden, 1);
  EXPECT_EQ(agreement.behind, 1);
  EXPECT_DOUBLE_EQ(agreement.AtDepthShare(), 0.4);
  EXPECT_DOUBLE_EQ(agreement.HiddenShare(), 0.2);
  EXPECT_DOUBLE_EQ(agreement.BehindShare(), 0.2);
  EXPECT_DOUBLE_EQ(agreement.UndrawnShare(), 0.2);
}

TEST(RenderMesh, TheNearestTriangleWinsAndColoursBlendPerspectiveCorrectly) {
  const CalibratedView view = Straight();
  TriangleMesh mesh;
  // A far red square over the whole view and a near slanted one, black at its left edge (depth
  // 2) and white at its right (depth 6), over columns 10..30.
  mesh.vertices = {Unproject(view, 0, 0, 10),  Unproject(view, 40, 0, 10), Unproject(view, 40, 30, 10),
                   Unproject(view, 0, 30, 10), Unproject(view, 10, 0, 2),  Unproject(view, 30, 0, 6),
                   Unproject(view, 30, 30, 6), Unproject(view, 10, 30, 2)};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
  mesh.colours = {{255, 0, 0}, {255, 0, 0}, {255, 0, 0}, {255, 0, 0},
                  {0, 0, 0},   {255, 255, 255}, {255, 255, 255}, {0, 0, 0}};
  const Rendering rendering = RenderMesh(mesh, view);
  EXPECT_EQ(rendering.image.at<cv::Vec3b>(15, 5), cv::Vec3b(255, 0, 0));
  EXPECT_NEAR(rendering.depth.at<float>(15, 5), 10.0f, 1e-4f);
  for (int col = 10; col < 30; ++col) {
    // Screen position s in [0, 1] across the slanted square; depth and colour follow the plane:
    // 1/z is linear in s, the colour is linear along the surface.
    const double s = (col + 0.5 - 10) / 20.0;
    const double z = 1.0 / ((1 - s) / 2.0 + s / 6.0);
    const double along = (z - 2.0) / 4.0;  // 0 at the black edge, 1 at the white one
    EXPECT_NEAR(rendering.depth.at<float>(15, col), z, 1e-4) << col;
    EXPECT_NEAR(rendering.image.at<cv::Vec3b>(15, col)[1], 255.0 * along, 1.0) << col;
  }
}

TEST(RenderMesh, TrianglesReachingBehindTheCameraAreSkipped) {
  const CalibratedView view = Straight();
  TriangleMesh mesh;
  mesh.vertices = {{-1, -1, 3}, {1, -1, 3}, {0, 1, -1}};
  mesh.triangles = {{0, 1, 2}};
  const Rendering rendering = RenderMesh(mesh, view);
  EXPECT_EQ(cv::countNonZero(rendering.silhouette), 0);
}

TEST(RenderMesh, FrontFacesAloneGiveAClosedMeshsDepthBuffer) {
  // A smoothed ball with a dent and a knob (a concave region and a second silhouette), as
  // MeshSolidVoxels makes it: closed, counter-clockwise seen from outside.
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1)), 40);
  std::vector<uint64_t> bits((grid.num_voxels() + 63) / 64, 0);
  for (int64_t i = 0; i < grid.num_voxels(); ++i) {
    const Eigen::Vector3d p = grid.Centre(grid.Voxel(i));
    const bool ball = p.norm() <= 0.6 && (p - Eigen::Vector3d(0.0, 0.0, -0.6)).norm() > 0.25;
    const bool knob = (p - Eigen::Vector3d(0.55, -0.4, -0.3)).norm() <= 0.2;
    if (ball || knob) bits[i / 64] |= uint64_t{1} << (i % 64);
  }
  const TriangleMesh mesh = MeshSolidVoxels(Volume(grid, std::move(bits)), SurfaceMeshOptions());
  ASSERT_GT(mesh.triangles.size(), 1000u);
  // Views from several sides, each at distance 3 looking at the origin.
  int pixels = 0, differing = 0, depth_only_differing = 0;
  for (const Eigen::Vector3d& centre :
       {Eigen::Vector3d(0, 0, -3), Eigen::Vector3d(2.1, 0.5, -2.1), Eigen::Vector3d(0, -3, 0.2),
        Eigen::Vector3d(-2.5, 1.0, 1.3)}) {
    const CalibratedView view = testing::PinholeViewLookingAtOrigin(centre, 160, 120, 120.0);
    const Rendering both = RenderMesh(mesh, view);
    const Rendering front = RenderMesh(mesh, view, /*front_faces_only=*/true);
    // The depth alone, as the sightings draw it: the same buffer.
    const cv::Mat depth_only = RenderMeshDepth(mesh, view, /*front_faces_only=*/true);
    ASSERT_GT(cv::countNonZero(both.silhouette), 1000);
    ASSERT_EQ(depth_only.size(), front.depth.size());
    for (int row = 0; row < view.height; ++row) {
      for (int col = 0; col < view.width; ++col) {
        ++pixels;
        differing += both.depth.at<float>(row, col) != front.depth.at<float>(row, col);
        depth_only_differing += depth_only.at<float>(row, col) != front.depth.at<float>(row, col);
      }
    }
  }
  EXPECT_EQ(differing, 0) << "of " << pixels << " pixels";
  EXPECT_EQ(depth_only_differing, 0) << "of " << pixels << " pixels";
  // A triangle turned away from the camera is drawn only with both sides.
  const CalibratedView view = Straight();
  TriangleMesh facing;
  facing.vertices = {Unproject(view, 10, 5, 4), Unproject(view, 30, 5, 4), Unproject(view, 20, 25, 4)};
  facing.triangles = {{0, 2, 1}};  // clockwise on the screen: its normal points to the camera
  EXPECT_GT(cv::countNonZero(RenderMesh(facing, view, true).silhouette), 0);
  facing.triangles = {{0, 1, 2}};
  EXPECT_EQ(cv::countNonZero(RenderMesh(facing, view, true).silhouette), 0);
  EXPECT_GT(cv::countNonZero(RenderMesh(facing, view).silhouette), 0);
}

TEST(DrawMeshParts, CountsThePartsOverEachPixelAndWhatEachCovers) {
  const CalibratedView view = Straight();
  // Part 0: pixels 5..25 x 5..15 at depth 4; part 1: 15..35 x 10..25 at depth 6 (behind it where
  // they overlap); part 2: two triangles far off to the side, never drawn.
  TriangleMesh mesh;
  mesh.vertices = {Unproject(view, 5, 5, 4),    Unproject(view, 25, 5, 4),   Unproject(view, 25, 15, 4),
                   Unproject(view, 5, 15, 4),   Unproject(view, 15, 10, 6),  Unproject(view, 35, 10, 6),
                   Unproject(view, 35, 25, 6),  Unproject(view, 15, 25, 6),  Unproject(view, 500, 0, 4),
                   Unproject(view, 520, 0, 4),  Unproject(view, 520, 20, 4)};
  // Wound as front faces (clockwise on the screen).
  mesh.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 6, 5}, {4, 7, 6}, {8, 10, 9}};
  const std::vector<int> part = {0, 0, 1, 1, 2};
  cv::Mat count, last;
  std::vector<int64_t> covered;
  DrawMeshParts(mesh, part, 3, view, &count, &last, &covered);
  ASSERT_EQ(covered.size(), 3u);
  EXPECT_EQ(covered[0], 20 * 10);
  EXPECT_EQ(covered[1], 20 * 15);
  EXPECT_EQ(covered[2], 0);
  for (int row = 0; row < view.height; ++row) {
    for (int col = 0; col < view.width; ++col) {
      const bool in0 = col >= 5 && col < 25 && row >= 5 && row < 15;
      const bool in1 = col >= 15 && col < 35 && row >= 10 && row < 25;
      ASSERT_EQ(count.at<uint8_t>(row, col), int(in0) + int(in1)) << col << "," << row;
      ASSERT_EQ(last.at<int>(row, col), in1 ? 1 : (in0 ? 0 : -1)) << col << "," << row;
    }
  }
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
