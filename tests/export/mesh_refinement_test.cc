// RefineMeshFromPhotos on a textured floor whose mesh lies half a voxel above it: photos from above
// move it down onto the floor; photos that all look from one side at a grazing angle cannot tell
// its offsets apart and do not judge it, photos from around at the same angle do.
#include "export/mesh_refinement.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "tests/test_support.h"

namespace raycarve {
namespace exporter {
namespace {

constexpr double kVoxel = 0.02;
constexpr double kCell = 0.01;  // the floor's cells
constexpr double kHalfSide = 0.2;  // the sheet's

// The floor z = 0, cells of kCell each of its own colour; grey where a ray misses it.
Eigen::Vector3d TraceFloor(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, bool* hit) {
  *hit = direction.z() < -1e-9;
  if (!*hit) return Eigen::Vector3d::Constant(128.0);
  const Eigen::Vector3d p = origin - origin.z() / direction.z() * direction;
  return testing::CellColour(static_cast<int>(std::floor(p.x() / kCell)),
                             static_cast<int>(std::floor(p.y() / kCell)), 7);
}

// A square sheet over [-kHalfSide, kHalfSide]^2 at `height`, facing up, vertices half a voxel
// apart.
TriangleMesh FloorSheet(double height) {
  TriangleMesh mesh;
  const int n = static_cast<int>(std::lround(2.0 * kHalfSide / (0.5 * kVoxel)));
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      mesh.vertices.emplace_back(-kHalfSide + i * 0.5 * kVoxel, -kHalfSide + j * 0.5 * kVoxel, height);
      mesh.colours.emplace_back(128, 128, 128);
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      mesh.triangles.emplace_back(a, b, d);
      mesh.triangles.emplace_back(a, d, c);
    }
  }
  ComputeVertexNormals(&mesh);
  return mesh;
}

// Photos (320 x 240, focal length 400) from (azimuth, elevation) pairs in degrees, `distance`
// from the sheet's centre.
std::vector<CalibratedView> FloorViews(const std::vector<std::pair<double, double>>& directions,
                                       double distance) {
  std::vector<CalibratedView> views;
  for (const auto& [azimuth, elevation] : directions) {
    const double a = azimuth * M_PI / 180.0, e = elevation * M_PI / 180.0;
    const Eigen::Vector3d centre =
        distance * Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
    CalibratedView view = testing::PinholeViewLookingAtOrigin(centre, 320, 240, 400.0);
    testing::TraceViewImage(&view, TraceFloor);
    views.push_back(std::move(view));
  }
  return views;
}

MeshRefinementOptions FloorOptions() {
  MeshRefinementOptions options;
  options.search_range = kVoxel;
  options.patch_radius = 0.5 * kVoxel;
  options.depth_tolerance = kVoxel;
  options.voxel_size = kVoxel;
  options.num_threads = 1;
  return options;
}

double MedianHeight(const TriangleMesh& mesh) {
  std::vector<double> heights;
  for (const Eigen::Vector3f& v : mesh.vertices) heights.push_back(std::abs(v.z()));
  std::nth_element(heights.begin(), heights.begin() + heights.size() / 2, heights.end());
  return heights[heights.size() / 2];
}

TEST(RefineMeshFromPhotos, PhotosFromAboveMoveALiftedFloorOntoIt) {
  TriangleMesh mesh = FloorSheet(0.5 * kVoxel);
  ASSERT_GT(mesh.normals[0].z(), 0.9f);
  const MeshRefinementSummary summary =
      RefineMeshFromPhotos(FloorViews({{10, 60}, {130, 60}, {250, 60}}, 0.8), FloorOptions(), &mesh);
  EXPECT_GT(summary.judged, static_cast<int64_t>(mesh.vertices.size() / 2));
  EXPECT_LT(summary.mean_offset, 0.0);
  // Half a voxel above it before.
  EXPECT_LT(MedianHeight(mesh), 0.2 * kVoxel);
}

// 6 away, 18-26 degrees above the floor: a pixel covers about 0.015 of it, 0.034-0.049 stretched
// by the tilt. From one azimuth, over the search range (0.02 either side) the photos' sampled
// points part by at most 0.02 x (tan 72 - tan 64) = 0.021: not told apart, no vertex is judged,
// and the sheet moves half a voxel in, once (the iso-surface's mean offset), whatever the photos
// show. From three azimuths at 22 degrees they part by 0.02 x tan 68 x sqrt(3) = 0.086: judged.
TEST(RefineMeshFromPhotos, PhotosFromOneSideAtAGrazingAngleDoNotJudgeThoseFromAroundDo) {
  TriangleMesh one_side = FloorSheet(0.5 * kVoxel);
  const MeshRefinementSummary from_one_side =
      RefineMeshFromPhotos(FloorViews({{10, 18}, {10, 22}, {10, 26}}, 6.0), FloorOptions(), &one_side);
  EXPECT_EQ(from_one_side.judged, 0);
  EXPECT_EQ(from_one_side.moved, 0);
  EXPECT_GT(from_one_side.unresolved, static_cast<int64_t>(one_side.vertices.size() / 2));
  for (const Eigen::Vector3f& v : one_side.vertices) {
    EXPECT_GE(v.z(), -1e-6f);
    EXPECT_LE(v.z(), static_cast<float>(0.5 * kVoxel) + 1e-6f);
  }
  EXPECT_LT(MedianHeight(one_side), 0.05 * kVoxel);

  TriangleMesh around = FloorSheet(0.5 * kVoxel);
  const MeshRefinementSummary from_around =
      RefineMeshFromPhotos(FloorViews({{10, 22}, {130, 22}, {250, 22}}, 6.0), FloorOptions(), &around);
  EXPECT_GT(from_around.judged, static_cast<int64_t>(around.vertices.size() / 2));
}

// On a grid finer than the photos' pixels: photos 0.8 away, 60 degrees above the floor, a pixel
// covers 0.002 of it (0.0023 tilted); a voxel of 0.001 is half a pixel. Over +-1 voxel the three
// photos' sampled points part by 0.001 x tan 30 x sqrt(3) = 0.001, under a pixel: no offset is
// told from another, each vertex moves half a voxel in once, and a sheet 2.5 pixels (0.005) up
// stays up. Searching +-3 pixels (0.006) they part by 0.006: judged, and the sheet comes down.
TEST(RefineMeshFromPhotos, ASearchOfAFewPixelsJudgesWhereASubPixelVoxelsCannot) {
  constexpr double kFine = 0.001, kLift = 0.005;
  const std::vector<CalibratedView> views = FloorViews({{10, 60}, {130, 60}, {250, 60}}, 0.8);
  MeshRefinementOptions options = FloorOptions();
  options.voxel_size = kFine;
  options.depth_tolerance = kFine;
  options.patch_radius = 0.5 * kFine;
  options.search_range = kFine;
  TriangleMesh by_voxel = FloorSheet(kLift);
  const MeshRefinementSummary voxel_search = RefineMeshFromPhotos(views, options, &by_voxel);
  EXPECT_GT(voxel_search.unresolved, static_cast<int64_t>(by_voxel.vertices.size() / 2));
  EXPECT_GT(MedianHeight(by_voxel), 0.6 * kLift);

  options.search_range = 0.006;
  TriangleMesh by_pixels = FloorSheet(kLift);
  const MeshRefinementSummary pixel_search = RefineMeshFromPhotos(views, options, &by_pixels);
  EXPECT_EQ(pixel_search.unresolved, 0);
  EXPECT_GT(pixel_search.judged, static_cast<int64_t>(by_pixels.vertices.size() / 2));
  EXPECT_LT(MedianHeight(by_pixels), 0.2 * kLift);  // within half a pixel of the floor
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
