#include "export/mesh_silhouettes.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "export/mesh_renderer.h"
#include "tests/test_support.h"

namespace raycarve {
namespace exporter {
namespace {

// A 160x120 pinhole view (f = 120) at `centre`, looking at the origin.
CalibratedView LookingAtOrigin(const Eigen::Vector3d& centre) {
  return testing::PinholeViewLookingAtOrigin(centre, 160, 120, 120.0);
}

// The fit's options for the 40-voxel grid of VoxelBall (voxels 0.05 wide).
SilhouetteFitOptions VoxelOptions() {
  SilhouetteFitOptions options;
  options.max_move = 0.05;
  options.depth_tolerance = 0.05;
  return options;
}

// The iso-surface of the voxels (a 40^3 grid over [-1, 1]^3, voxels 0.05 wide) within `radius`
// of `centre`.
TriangleMesh VoxelBall(const Eigen::Vector3d& centre, double radius) {
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1)), 40);
  std::vector<uint64_t> bits((grid.num_voxels() + 63) / 64, 0);
  for (int64_t i = 0; i < grid.num_voxels(); ++i) {
    if ((grid.Centre(grid.Voxel(i)) - centre).norm() <= radius) bits[i / 64] |= uint64_t{1} << (i % 64);
  }
  TriangleMesh mesh = MeshSolidVoxels(Volume(grid, std::move(bits)), SurfaceMeshOptions());
  ComputeVertexNormals(&mesh);
  return mesh;
}

TriangleMesh Join(const TriangleMesh& a, const TriangleMesh& b) {
  TriangleMesh joined = a;
  const int offset = static_cast<int>(a.vertices.size());
  joined.vertices.insert(joined.vertices.end(), b.vertices.begin(), b.vertices.end());
  joined.normals.insert(joined.normals.end(), b.normals.begin(), b.normals.end());
  for (const Eigen::Vector3i& t : b.triangles) joined.triangles.push_back(t + Eigen::Vector3i::Constant(offset));
  return joined;
}

// The pixels whose centre's ray meets the sphere.
cv::Mat SphereMask(const CalibratedView& view, const Eigen::Vector3d& centre, double radius) {
  cv::Mat mask(view.height, view.width, CV_8UC1, cv::Scalar(0));
  const Eigen::Matrix3d world_from_cam = view.cam_from_world.rotation.toRotationMatrix().transpose();
  for (int row = 0; row < view.height; ++row) {
    for (int col = 0; col < view.width; ++col) {
      const Eigen::Vector3d ray =
          (world_from_cam * view.K.inverse() * Eigen::Vector3d(col + 0.5, row + 0.5, 1.0)).normalized();
      const Eigen::Vector3d to_centre = centre - view.centre;
      const double along = to_centre.dot(ray);
      if (along > 0.0 && (to_centre - along * ray).norm() <= radius) mask.at<uint8_t>(row, col) = 255;
    }
  }
  return mask;
}

cv::Mat Covered(const TriangleMesh& mesh, const CalibratedView& view) {
  const cv::Mat depth = RenderMeshDepth(mesh, view, /*front_faces_only=*/true);
  cv::Mat covered(depth.size(), CV_8UC1, cv::Scalar(0));
  for (int row = 0; row < depth.rows; ++row) {
    for (int col = 0; col < depth.cols; ++col) {
      if (std::isfinite(depth.at<float>(row, col))) covered.at<uint8_t>(row, col) = 255;
    }
  }
  return covered;
}

std::vector<CalibratedView> Ring(int count, double elevation) {
  std::vector<CalibratedView> views;
  for (int k = 0; k < count; ++k) {
    const double angle = 2.0 * M_PI * k / count;
    views.push_back(LookingAtOrigin(3.0 * Eigen::Vector3d(std::cos(angle), elevation, std::sin(angle)).normalized()));
  }
  return views;
}

TEST(FitMeshToSilhouettes, AFatBallIsPulledInOntoItsMasksAndNeverPushedOut) {
  // The object: a sphere of radius 0.5. The mesh: the voxels within 0.58 (1.6 voxels fat).
  std::vector<CalibratedView> views = Ring(8, 0.3);
  for (CalibratedView& view : views) view.mask = SphereMask(view, Eigen::Vector3d::Zero(), 0.5);
  TriangleMesh mesh = VoxelBall(Eigen::Vector3d::Zero(), 0.58);
  const TriangleMesh before = mesh;
  int64_t outside_before = 0, missing_before = 0, object = 0;
  for (const CalibratedView& view : views) {
    const cv::Mat covered = Covered(mesh, view);
    outside_before += cv::countNonZero(covered & ~view.mask);
    missing_before += cv::countNonZero(view.mask & ~covered);
    object += cv::countNonZero(view.mask);
  }
  ASSERT_GT(outside_before, object / 10);  // the fat outline the fit is for
  const SilhouetteFitSummary summary = FitMeshToSilhouettes(views, VoxelOptions(), &mesh);
  EXPECT_EQ(summary.passes, 2);
  EXPECT_EQ(summary.masked_views, 8);
  EXPECT_GT(summary.pulled_vertices, summary.outline_vertices / 2);
  EXPECT_GT(summary.mean_outside_pixels_first, 1.0);
  EXPECT_LT(summary.mean_outside_pixels_last, 0.6 * summary.mean_outside_pixels_first);
  int64_t outside_after = 0, missing_after = 0;
  for (const CalibratedView& view : views) {
    const cv::Mat covered = Covered(mesh, view);
    outside_after += cv::countNonZero(covered & ~view.mask);
    missing_after += cv::countNonZero(view.mask & ~covered);
  }
  // Most of the outline beyond the masks goes, and the masks stay covered.
  EXPECT_LT(outside_after, outside_before / 3) << outside_before;
  EXPECT_LE(missing_after, missing_before + object / 100) << missing_before;
  // Every vertex moved inwards along its normal, if at all, and by at most two passes' reach.
  ASSERT_EQ(mesh.vertices.size(), before.vertices.size());
  ASSERT_EQ(mesh.triangles, before.triangles);
  int moved = 0;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3f step = mesh.vertices[i] - before.vertices[i];
    EXPECT_LE(step.dot(before.normals[i]), 1e-4f) << i;
    EXPECT_LE(step.norm(), 0.1f + 1e-4f) << i;
    moved += step.norm() > 1e-4f;
  }
  EXPECT_GT(moved, 0);
}

TEST(FitMeshToSilhouettes, AMeshOnItsOwnSilhouettesBarelyMoves) {
  std::vector<CalibratedView> views = Ring(8, 0.3);
  TriangleMesh mesh = VoxelBall(Eigen::Vector3d::Zero(), 0.5);
  for (CalibratedView& view : views) view.mask = Covered(mesh, view);
  const TriangleMesh before = mesh;
  const SilhouetteFitSummary summary = FitMeshToSilhouettes(views, VoxelOptions(), &mesh);
  EXPECT_LT(summary.mean_outside_pixels_first, 0.5);
  EXPECT_LT(summary.mean_move, 0.2 * 0.05);
  for (const CalibratedView& view : views) {
    const cv::Mat covered = Covered(mesh, view);
    const double iou = static_cast<double>(cv::countNonZero(covered & view.mask)) /
                       cv::countNonZero(covered | view.mask);
    EXPECT_GT(iou, 0.98);
  }
}

TEST(FitMeshToSilhouettes, ABallThinnerThanItsMasksIsLeftAlone) {
  // The masks' object pixels a mesh misses are not the fit's to fill (it only pulls in).
  std::vector<CalibratedView> views = Ring(8, 0.3);
  for (CalibratedView& view : views) view.mask = SphereMask(view, Eigen::Vector3d::Zero(), 0.5);
  TriangleMesh mesh = VoxelBall(Eigen::Vector3d::Zero(), 0.42);
  const TriangleMesh before = mesh;
  const SilhouetteFitSummary summary = FitMeshToSilhouettes(views, VoxelOptions(), &mesh);
  EXPECT_GT(summary.outline_vertices, 100);
  EXPECT_EQ(summary.pulled_vertices, 0);
  EXPECT_EQ(mesh.vertices, before.vertices);
}

TEST(FitMeshToSilhouettes, TheRimOfASeeThroughHoleIsLeftAlone) {
  // A washer about the z axis (radii 0.2 to 0.55, 0.4 thick) seen through its hole by cameras
  // in front of it; the masks are a thinner washer's (0.3 to 0.5): the outer rim stands beyond
  // them and is pulled in, and the hole, smaller in the mesh than in the masks (as a hole in a
  // mask cut from a backdrop the object shares colours with would make it), is not widened.
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1)), 40);
  auto washer = [&grid](double inner, double outer) {
    std::vector<uint64_t> bits((grid.num_voxels() + 63) / 64, 0);
    for (int64_t i = 0; i < grid.num_voxels(); ++i) {
      const Eigen::Vector3d p = grid.Centre(grid.Voxel(i));
      const double r = p.head<2>().norm();
      if (r >= inner && r <= outer && std::abs(p.z()) <= 0.2) bits[i / 64] |= uint64_t{1} << (i % 64);
    }
    TriangleMesh mesh = MeshSolidVoxels(Volume(grid, std::move(bits)), SurfaceMeshOptions());
    ComputeVertexNormals(&mesh);
    return mesh;
  };
  TriangleMesh mesh = washer(0.2, 0.55);
  const TriangleMesh thin = washer(0.3, 0.5);
  std::vector<CalibratedView> views;
  for (int k = 0; k < 5; ++k) {
    const double angle = -0.2 + 0.4 * k / 4.0;
    views.push_back(LookingAtOrigin(3.0 * Eigen::Vector3d(std::sin(angle), 0.05, -std::cos(angle)).normalized()));
    views.back().mask = Covered(thin, views.back());
    // The premise: the hole is see-through in the mesh's own drawing.
    const cv::Mat covered = Covered(mesh, views.back());
    ASSERT_EQ(covered.at<uint8_t>(views.back().height / 2, views.back().width / 2), 0) << k;
  }
  const TriangleMesh before = mesh;
  FitMeshToSilhouettes(views, VoxelOptions(), &mesh);
  int outer_moved = 0, inner_moved = 0;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const double r = before.vertices[i].head<2>().norm();
    const bool moved = (mesh.vertices[i] - before.vertices[i]).norm() > 1e-4f;
    if (r > 0.5) outer_moved += moved;
    if (r < 0.3) inner_moved += moved;
  }
  EXPECT_GT(outer_moved, 100);
  EXPECT_EQ(inner_moved, 0);
}

TEST(FitMeshToSilhouettes, NoMasksNothingMoves) {
  const std::vector<CalibratedView> views = Ring(4, 0.3);
  TriangleMesh mesh = VoxelBall(Eigen::Vector3d::Zero(), 0.5);
  const TriangleMesh before = mesh;
  const SilhouetteFitSummary summary = FitMeshToSilhouettes(views, VoxelOptions(), &mesh);
  EXPECT_EQ(summary.passes, 0);
  EXPECT_EQ(mesh.vertices, before.vertices);
}

TEST(RemoveUnneededParts, APhantomNoMaskNeedsGoesAndASeparateObjectStays) {
  // Cameras on an arc in front of (z < 0) a ball of radius 0.45; a small ball behind it (the
  // phantom every camera sees within the ball's silhouette) and another beside it (an object).
  std::vector<CalibratedView> views;
  for (int k = 0; k < 6; ++k) {
    const double angle = -0.35 + 0.7 * k / 5.0;
    views.push_back(LookingAtOrigin(3.0 * Eigen::Vector3d(std::sin(angle), 0.1, -std::cos(angle)).normalized()));
  }
  const TriangleMesh ball = VoxelBall(Eigen::Vector3d::Zero(), 0.45);
  const TriangleMesh phantom = VoxelBall(Eigen::Vector3d(0.0, 0.0, 0.75), 0.12);
  const TriangleMesh object = VoxelBall(Eigen::Vector3d(0.0, -0.75, -0.2), 0.15);
  for (CalibratedView& view : views) {
    const cv::Mat ball_covered = Covered(ball, view);
    // The set-up's premise: the phantom never shows beside the ball, the object mostly does.
    ASSERT_EQ(cv::countNonZero(Covered(phantom, view) & ~ball_covered), 0);
    const cv::Mat object_covered = Covered(object, view);
    ASSERT_GT(cv::countNonZero(object_covered & ~ball_covered), cv::countNonZero(object_covered) / 2);
    view.mask = ball_covered | object_covered;
  }
  const TriangleMesh all = Join(Join(ball, phantom), object);
  TriangleMesh mesh = all;
  const MeshPartsSummary summary = RemoveUnneededParts(views, 2, {}, 0.0, 0, &mesh);
  EXPECT_EQ(summary.parts, 3);
  EXPECT_EQ(summary.removed, 1);
  EXPECT_EQ(summary.removed_vertices, static_cast<int64_t>(phantom.vertices.size()));
  ASSERT_EQ(mesh.vertices.size(), ball.vertices.size() + object.vertices.size());
  ASSERT_EQ(mesh.normals.size(), mesh.vertices.size());
  EXPECT_EQ(mesh.triangles.size(), ball.triangles.size() + object.triangles.size());
  for (const Eigen::Vector3f& v : mesh.vertices) EXPECT_LT(v.z(), 0.55f);  // nothing of the phantom
  // A sparse point on the phantom's surface keeps it (a feature the photos matched there).
  mesh = all;
  const MeshPartsSummary anchored = RemoveUnneededParts(
      views, 2, {Eigen::Vector3d(0.0, 0.0, 0.75 - 0.12)}, 0.075, 0, &mesh);
  EXPECT_EQ(anchored.removed, 0);
  EXPECT_EQ(anchored.anchored, 1);
  EXPECT_EQ(mesh.vertices.size(), all.vertices.size());
  // A point far from every small part keeps nothing.
  mesh = all;
  EXPECT_EQ(RemoveUnneededParts(views, 2, {Eigen::Vector3d(0.9, 0.9, 0.9)}, 0.075, 0, &mesh).removed, 1);
  // 0 keeps every part, and so do too few masked views.
  mesh = all;
  EXPECT_EQ(RemoveUnneededParts(views, 0, {}, 0.0, 0, &mesh).removed, 0);
  EXPECT_EQ(mesh.vertices.size(), all.vertices.size());
  std::vector<CalibratedView> one_mask = views;
  for (size_t v = 1; v < one_mask.size(); ++v) one_mask[v].mask = cv::Mat();
  EXPECT_EQ(RemoveUnneededParts(one_mask, 2, {}, 0.0, 0, &mesh).removed, 0);
  EXPECT_EQ(mesh.vertices.size(), all.vertices.size());
}

TEST(RemoveUnneededParts, WithoutMasksSpecksGoUnlessASparsePointIsTheirs) {
  // A ball (the model), three specks of a voxel or two, and a separate small object.
  const TriangleMesh ball = VoxelBall(Eigen::Vector3d::Zero(), 0.7);
  const TriangleMesh lone = VoxelBall(Eigen::Vector3d(0.0, 0.0, 0.88), 0.06);
  const TriangleMesh featured = VoxelBall(Eigen::Vector3d(0.0, 0.88, 0.0), 0.06);
  const TriangleMesh beside = VoxelBall(Eigen::Vector3d(-0.84, 0.0, 0.0), 0.06);
  const TriangleMesh object = VoxelBall(Eigen::Vector3d(0.72, 0.72, 0.72), 0.15);
  ASSERT_LT(lone.vertices.size(), kSpeckShare * ball.vertices.size());
  ASSERT_GT(object.vertices.size(), kSpeckShare * ball.vertices.size());
  const TriangleMesh all = Join(Join(Join(Join(ball, lone), featured), beside), object);
  const std::vector<CalibratedView> views = {LookingAtOrigin(Eigen::Vector3d(0.0, 0.0, -3.0))};
  // A sparse point on the featured speck's surface, and one on the ball's surface facing the
  // speck beside it (nearer the ball: the ball's).
  const std::vector<Eigen::Vector3d> anchors = {Eigen::Vector3d(0.0, 0.82, 0.0),
                                                Eigen::Vector3d(-0.7, 0.0, 0.0)};
  TriangleMesh mesh = all;
  const MeshPartsSummary summary = RemoveUnneededParts(views, 2, anchors, 0.125, 0, &mesh);
  EXPECT_FALSE(summary.judged_by_masks);
  EXPECT_EQ(summary.parts, 5);
  EXPECT_EQ(summary.removed, 2);
  EXPECT_EQ(summary.anchored, 1);
  EXPECT_EQ(summary.removed_vertices, static_cast<int64_t>(lone.vertices.size() + beside.vertices.size()));
  ASSERT_EQ(mesh.vertices.size(), ball.vertices.size() + featured.vertices.size() + object.vertices.size());
  for (const Eigen::Vector3f& v : mesh.vertices) {
    EXPECT_FALSE(v.z() > 0.75f && v.x() < 0.5f);  // nothing of the lone speck
    EXPECT_GT(v.x(), -0.76f);                    // nor of the one beside the ball
  }
  // With no sparse points at all there is nothing to judge by: everything stays.
  mesh = all;
  EXPECT_EQ(RemoveUnneededParts(views, 2, {}, 0.125, 0, &mesh).removed, 0);
  EXPECT_EQ(mesh.vertices.size(), all.vertices.size());
  // SpeckVertices (what the box's walls' removal uses) marks the same two specks' vertices.
  const std::vector<uint8_t> speck = SpeckVertices(all, anchors, 0.125);
  ASSERT_EQ(speck.size(), all.vertices.size());
  size_t offset = ball.vertices.size();
  for (const TriangleMesh* part : {&lone, &featured, &beside, &object}) {
    const bool expected = part == &lone || part == &beside;
    for (size_t i = 0; i < part->vertices.size(); ++i) EXPECT_EQ(speck[offset + i], expected);
    offset += part->vertices.size();
  }
  for (size_t i = 0; i < ball.vertices.size(); ++i) EXPECT_EQ(speck[i], 0);
  const std::vector<uint8_t> without_anchors = SpeckVertices(all, {}, 0.125);
  EXPECT_EQ(std::count(without_anchors.begin(), without_anchors.end(), 1), 0);
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
