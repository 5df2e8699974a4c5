#include "export/carve_export.h"

#include <filesystem>

#include <gtest/gtest.h>
#include <pcl/PolygonMesh.h>
#include <pcl/conversions.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>

#include "samples/synthetic_scene.h"
#include "tests/carve/carve_fixture.h"
#include "tests/test_support.h"

namespace raycarve {
namespace exporter {
namespace {

CarveResult SmallCarve() {
  const SyntheticScene scene = GenerateSyntheticScene(testing::SceneOptions(6, 160, 120));
  CarveOptions carve;
  carve.resolution = 48;
  return CarveVolume(testing::SceneViews(scene), scene.object_box, carve);
}

TEST(CarveExport, CloudHoldsJudgedSurfaceVoxelsWithOutwardNormals) {
  const CarveResult result = SmallCarve();
  const std::vector<ColouredPoint> points = SurfacePoints(result, 2);
  int judged = 0;
  for (const ColouredVoxel& voxel : result.surface) judged += voxel.num_views >= 2;
  ASSERT_EQ(static_cast<int>(points.size()), judged);
  ASSERT_GT(points.size(), 500u);
  EXPECT_GT(SurfacePoints(result, 1).size(), points.size());
  // Normals point to the empty side: a step along the normal leaves the solid volume.
  const VoxelGrid& grid = result.volume.grid();
  int outward = 0, with_normal = 0;
  for (const ColouredPoint& point : points) {
    if (point.normal.norm() == 0.0f) continue;
    ++with_normal;
    EXPECT_NEAR(point.normal.norm(), 1.0f, 1e-5f);
    const Eigen::Vector3d ahead = point.xyz.cast<double>() + 1.5 * grid.voxel_size() * point.normal.cast<double>();
    outward += !result.volume.IsSolid(grid.VoxelOf(ahead));
  }
  EXPECT_GT(static_cast<double>(outward) / with_normal, 0.9);
}

TEST(CarveExport, FilesOpenWithPCLAndHaveTheExpectedFields) {
  const CarveResult result = SmallCarve();
  const std::string folder = testing::MakeTemporaryDirectory("carve_export");
  const std::vector<ColouredPoint> points = SurfacePoints(result, 2);
  WritePointCloudPly(points, folder + "/cloud.ply");
  const MeshSummary summary = WriteVoxelMeshPly(result, folder + "/mesh.ply");

  pcl::PCLPointCloud2 cloud;
  ASSERT_EQ(pcl::io::loadPLYFile(folder + "/cloud.ply", cloud), 0);
  EXPECT_EQ(cloud.width * cloud.height, points.size());
  std::vector<std::string> fields;
  for (const pcl::PCLPointField& field : cloud.fields) fields.push_back(field.name);
  for (const char* name : {"x", "y", "z", "normal_x", "normal_y", "normal_z", "rgb"}) {
    EXPECT_NE(std::find(fields.begin(), fields.end(), name), fields.end()) << name;
  }

  pcl::PolygonMesh mesh;
  ASSERT_EQ(pcl::io::loadPLYFile(folder + "/mesh.ply", mesh), 0);
  EXPECT_EQ(mesh.polygons.size(), summary.num_triangles);
  EXPECT_EQ(mesh.cloud.width * mesh.cloud.height, summary.num_vertices);
  EXPECT_EQ(summary.num_vertices, 2 * summary.num_triangles);  // 4 vertices, 2 triangles a face
  pcl::PointCloud<pcl::PointXYZRGB> vertices;
  pcl::fromPCLPointCloud2(mesh.cloud, vertices);
  // Every vertex lies on the carved grid's corners, inside the grid's box.
  const Eigen::AlignedBox3d box = result.volume.grid().Box();
  for (const pcl::PointXYZRGB& vertex : vertices) {
    ASSERT_TRUE(box.contains(Eigen::Vector3d(vertex.x, vertex.y, vertex.z)));
  }
  std::filesystem::remove_all(folder);
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
