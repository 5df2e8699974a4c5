#include "export/surface_mesh.h"

#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "carve/volume.h"
#include "carve/voxel_grid.h"
#include "tests/test_support.h"

namespace raycarve {
namespace exporter {
namespace {

// A volume over [-1, 1]^3 at `resolution` whose solid voxels are those where `inside` holds at
// the voxel centre.
template <typename Inside>
Volume MakeVolume(int resolution, Inside inside) {
  const VoxelGrid grid(Eigen::AlignedBox3d(Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1)),
                       resolution);
  std::vector<uint64_t> bits((grid.num_voxels() + 63) / 64, 0);
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    if (inside(grid.Centre(grid.Voxel(index)))) bits[index >> 6] |= uint64_t{1} << (index & 63);
  }
  return Volume(grid, std::move(bits));
}

Volume Ball(int resolution, double radius) {
  return MakeVolume(resolution, [radius](const Eigen::Vector3d& p) { return p.norm() <= radius; });
}

double MaxEdgeLength(const TriangleMesh& mesh) {
  double longest = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      longest = std::max(longest, static_cast<double>(
                                      (mesh.vertices[t[k]] - mesh.vertices[t[(k + 1) % 3]]).norm()));
    }
  }
  return longest;
}

TEST(SurfaceMesh, ABallOfVoxelsBecomesOneClosedManifoldSphereWithOutwardNormals) {
  const double radius = 0.7;
  const Volume volume = Ball(40, radius);
  const double voxel = volume.grid().voxel_size();
  SurfaceMeshSummary summary;
  const TriangleMesh mesh = MeshSolidVoxels(volume, SurfaceMeshOptions(), &summary);
  ASSERT_FALSE(mesh.empty());
  EXPECT_EQ(summary.triangles, static_cast<int64_t>(mesh.triangles.size()));
  const MeshTopology topology = AnalyseTopology(mesh);
  EXPECT_TRUE(topology.IsClosedManifold())
      << topology.boundary_edges << " boundary, " << topology.non_manifold_edges
      << " non-manifold edges, " << topology.non_manifold_vertices << " non-manifold vertices, "
      << topology.inconsistent_edges << " inconsistent";
  EXPECT_EQ(topology.components, 1);
  // Euler characteristic of a sphere: V - E + F = 2.
  EXPECT_EQ(static_cast<int64_t>(mesh.vertices.size()) - topology.edges +
                static_cast<int64_t>(mesh.triangles.size()),
            2);
  ASSERT_EQ(mesh.normals.size(), mesh.vertices.size());
  double worst_radial = 0.0, worst_stair = 0.0;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d p = mesh.vertices[i].cast<double>();
    const Eigen::Vector3d n = mesh.normals[i].cast<double>();
    EXPECT_NEAR(n.norm(), 1.0, 1e-5);
    // Outward: the normal points away from the ball's centre, close to the true normal.
    worst_radial = std::max(worst_radial, 1.0 - n.dot(p.normalized()));
    worst_stair = std::max(worst_stair, std::abs(p.norm() - radius));
  }
  // The voxel faces' corners lie up to sqrt(3)/2 voxel off the sphere (0.87) and their normals
  // are axis-aligned (up to 1 - 1/sqrt(3) = 0.42 off); smoothed, the mesh is within half a voxel
  // and its normals within 0.05 (about 18 degrees) of the truth. Measured: 0.36 voxel, 0.02.
  EXPECT_LT(worst_stair / voxel, 0.5);
  EXPECT_LT(worst_radial, 0.05);
  // Winding and normals agree: the normals from the faces' winding point the same way.
  TriangleMesh from_winding = mesh;
  ComputeVertexNormals(&from_winding);
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    ASSERT_GT(from_winding.normals[i].dot(mesh.normals[i]), 0.9f) << "vertex " << i;
  }
}

TEST(SurfaceMesh, AHollowBallsInnerSurfaceFacesIntoTheCavity) {
  // A shell between radii 0.35 and 0.75: its mesh has two closed parts, and every normal points
  // away from the solid: outwards on the outer sphere, towards the centre on the inner one.
  const double inner = 0.35, outer = 0.75;
  const Volume volume = MakeVolume(40, [&](const Eigen::Vector3d& p) {
    return p.norm() >= inner && p.norm() <= outer;
  });
  const TriangleMesh mesh = MeshSolidVoxels(volume, SurfaceMeshOptions(), nullptr);
  ASSERT_FALSE(mesh.empty());
  const MeshTopology topology = AnalyseTopology(mesh);
  EXPECT_TRUE(topology.IsClosedManifold());
  EXPECT_EQ(topology.components, 2);
  ASSERT_EQ(mesh.normals.size(), mesh.vertices.size());
  int on_inner = 0, on_outer = 0;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d p = mesh.vertices[i].cast<double>();
    const double radial = mesh.normals[i].cast<double>().dot(p.normalized());
    if (p.norm() < 0.5 * (inner + outer)) {
      ++on_inner;
      ASSERT_LT(radial, -0.9) << "inner vertex " << i;
    } else {
      ++on_outer;
      ASSERT_GT(radial, 0.9) << "outer vertex " << i;
    }
  }
  EXPECT_GT(on_inner, 100);
  EXPECT_GT(on_outer, on_inner);
}

TEST(SurfaceMesh, VertexNormalsWeighFacesByAreaOrOnceEach) {
  // Two triangles meet at vertex 0: a large one in the plane z = 0 (normal +z) and a small one in
  // the plane x = 0 (normal +x). By area the large one wins; once each, the normal bisects.
  TriangleMesh mesh;
  mesh.vertices = {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(10, 0, 0), Eigen::Vector3f(0, 10, 0),
                   Eigen::Vector3f(0, 0, 1), Eigen::Vector3f(0, 1, 0)};
  mesh.triangles = {Eigen::Vector3i(0, 1, 2), Eigen::Vector3i(0, 4, 3)};
  ComputeVertexNormals(&mesh, NormalWeighting::kPerFace);
  EXPECT_NEAR(mesh.normals[0].x(), std::sqrt(0.5), 1e-6);
  EXPECT_NEAR(mesh.normals[0].z(), std::sqrt(0.5), 1e-6);
  ComputeVertexNormals(&mesh, NormalWeighting::kByArea);
  // Areas 50 and 0.5: the normal is (0.5, 0, 50) normalised.
  EXPECT_NEAR(mesh.normals[0].x(), 0.5 / std::hypot(0.5, 50.0), 1e-6);
  EXPECT_NEAR(mesh.normals[0].z(), 50.0 / std::hypot(0.5, 50.0), 1e-6);
  EXPECT_NEAR(mesh.normals[3].x(), 1.0, 1e-6);  // only in the small triangle
}

TEST(SurfaceMesh, TheLibrariesThreadsAreLimitedAndTheMeshIsTheSameOnAnyCount) {
  const Volume volume = Ball(40, 0.7);
  SetLibraryThreads(1);
  EXPECT_EQ(cv::getNumThreads(), 1);
  const TriangleMesh one = MeshSolidVoxels(volume, SurfaceMeshOptions(), nullptr);
  SetLibraryThreads(3);
  EXPECT_EQ(cv::getNumThreads(), 3);
  const TriangleMesh three = MeshSolidVoxels(volume, SurfaceMeshOptions(), nullptr);
  SetLibraryThreads(-1);  // every core again, for the tests after this one
  ASSERT_FALSE(one.empty());
  ASSERT_EQ(one.vertices.size(), three.vertices.size());
  ASSERT_EQ(one.triangles.size(), three.triangles.size());
  for (size_t i = 0; i < one.vertices.size(); ++i) {
    ASSERT_EQ(one.vertices[i], three.vertices[i]) << "vertex " << i;
  }
  EXPECT_EQ(one.triangles, three.triangles);
}

TEST(SurfaceMesh, AveragingOverNeighboursIsTheSameOnAnyNumberOfThreads) {
  const TriangleMesh mesh = MeshSolidVoxels(Ball(112, 0.7), SurfaceMeshOptions(), nullptr);
  ASSERT_GT(mesh.vertices.size(), 3 * 8192u);  // enough that three threads take a share each
  const std::vector<std::vector<int>> neighbours = VertexNeighbours(mesh);
  std::vector<float> start(mesh.vertices.size());
  for (size_t i = 0; i < start.size(); ++i) start[i] = mesh.vertices[i].x() > 0.1f ? 1.0f : 0.0f;
  // Two passes by hand.
  std::vector<float> expected = start;
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<float> next(expected.size());
    for (size_t i = 0; i < expected.size(); ++i) {
      double sum = expected[i];
      for (int j : neighbours[i]) sum += expected[j];
      next[i] = static_cast<float>(sum / (1 + neighbours[i].size()));
    }
    expected = next;
  }
  for (int threads : {1, 3}) {
    std::vector<float> values = start;
    AverageOverNeighbours(neighbours, 2, &values, threads);
    EXPECT_EQ(values, expected) << threads << " threads";
  }
}

TEST(SurfaceMesh, SeparateSolidsAreSeparateComponentsAndTheGridBorderClosesTheMesh) {
  // Two boxes, one of them cut by the grid's border on three sides.
  const Volume volume = MakeVolume(24, [](const Eigen::Vector3d& p) {
    const bool first = (p.array() > -0.6).all() && (p.array() < -0.1).all();
    const bool second = (p.array() > 0.3).all();
    return first || second;
  });
  const TriangleMesh mesh = MeshSolidVoxels(volume, SurfaceMeshOptions());
  const MeshTopology topology = AnalyseTopology(mesh);
  EXPECT_TRUE(topology.IsClosedManifold());
  EXPECT_EQ(topology.components, 2);
  // Where the second box meets the border, its normals point out of the grid, not into it.
  const double top = volume.grid().Box().max().x();
  int at_border = 0;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (mesh.vertices[i].x() < top - 0.5 * volume.grid().voxel_size()) continue;
    ++at_border;
    if (mesh.vertices[i].y() > 0.5 && mesh.vertices[i].z() > 0.5) {
      EXPECT_GT(mesh.normals[i].x(), 0.5f);
    }
  }
  EXPECT_GT(at_border, 0);
}

TEST(SurfaceMesh, ComponentsSmallerThanAGivenSizeAreRemoved) {
  // A ball and a lone voxel (its iso-surface: an octahedron of 6 vertices).
  const Volume volume = MakeVolume(20, [](const Eigen::Vector3d& p) {
    return (p - Eigen::Vector3d(-0.4, 0, 0)).norm() < 0.4 ||
           (p - Eigen::Vector3d(0.75, 0.75, 0.75)).norm() < 0.05;
  });
  TriangleMesh mesh = MeshSolidVoxels(volume, SurfaceMeshOptions());
  ASSERT_EQ(AnalyseTopology(mesh).components, 2);
  const size_t before = mesh.vertices.size();
  EXPECT_EQ(RemoveSmallComponents(6, &mesh), 0);
  EXPECT_EQ(mesh.vertices.size(), before);
  EXPECT_EQ(RemoveSmallComponents(24, &mesh), 1);
  EXPECT_EQ(mesh.vertices.size(), before - 6);
  EXPECT_EQ(mesh.normals.size(), mesh.vertices.size());
  const MeshTopology topology = AnalyseTopology(mesh);
  EXPECT_EQ(topology.components, 1);
  EXPECT_TRUE(topology.IsClosedManifold());
  for (const Eigen::Vector3f& v : mesh.vertices) EXPECT_LT(v.x(), 0.5f);
}

TEST(SurfaceMesh, TheTopologyCheckFindsOpenAndNonManifoldMeshes) {
  TriangleMesh open;
  open.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  open.triangles = {{0, 1, 2}, {0, 2, 3}};
  MeshTopology topology = AnalyseTopology(open);
  EXPECT_EQ(topology.boundary_edges, 4);
  EXPECT_FALSE(topology.IsClosedManifold());
  // A closed tetrahedron passes; a third triangle on one of its edges does not.
  TriangleMesh tetrahedron = open;
  tetrahedron.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  topology = AnalyseTopology(tetrahedron);
  EXPECT_TRUE(topology.IsClosedManifold());
  EXPECT_EQ(topology.components, 1);
  TriangleMesh fin = tetrahedron;
  fin.vertices.push_back({1, 1, 1});
  fin.triangles.push_back({0, 1, 4});
  topology = AnalyseTopology(fin);
  EXPECT_EQ(topology.non_manifold_edges, 1);
  EXPECT_FALSE(topology.IsClosedManifold());
  // One triangle turned over: its edges run the same way as their neighbours'.
  TriangleMesh flipped = tetrahedron;
  flipped.triangles[3] = {1, 3, 2};
  topology = AnalyseTopology(flipped);
  EXPECT_EQ(topology.inconsistent_edges, 3);
  EXPECT_FALSE(topology.IsClosedManifold());
  // Two tetrahedra sharing one vertex: a pinched, non-manifold vertex.
  TriangleMesh pinched = tetrahedron;
  pinched.vertices.insert(pinched.vertices.end(), {{-1, 0, 0}, {0, -1, 0}, {0, 0, -1}});
  for (const Eigen::Vector3i& t : tetrahedron.triangles) {
    Eigen::Vector3i u = t;
    for (int k = 0; k < 3; ++k) u[k] = t[k] == 0 ? 0 : t[k] + 3;
    pinched.triangles.push_back(u);
  }
  topology = AnalyseTopology(pinched);
  EXPECT_EQ(topology.non_manifold_vertices, 1);
  EXPECT_FALSE(topology.IsClosedManifold());
}

TEST(SurfaceMesh, SplittingAndAFaceBudgetKeepTheMeshClosed) {
  const Volume volume = Ball(32, 0.7);
  const double voxel = volume.grid().voxel_size();
  const TriangleMesh plain = MeshSolidVoxels(volume, SurfaceMeshOptions());
  // Splitting and decimation keep flying edges' winding, which the normals follow: outwards.
  const auto outwards = [](const TriangleMesh& mesh) {
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      if (!(mesh.normals[i].dot(mesh.vertices[i].normalized()) > 0.5f)) return false;
    }
    return mesh.normals.size() == mesh.vertices.size() && !mesh.vertices.empty();
  };

  SurfaceMeshOptions split;
  split.max_edge_length = 0.4 * voxel;
  const TriangleMesh fine = MeshSolidVoxels(volume, split);
  EXPECT_LE(MaxEdgeLength(fine), split.max_edge_length * 1.0001);
  EXPECT_GT(fine.triangles.size(), 2 * plain.triangles.size());
  EXPECT_TRUE(AnalyseTopology(fine).IsClosedManifold());
  EXPECT_TRUE(outwards(fine));

  SurfaceMeshOptions budget;
  budget.max_triangles = static_cast<int64_t>(plain.triangles.size() / 4);
  const TriangleMesh coarse = MeshSolidVoxels(volume, budget);
  EXPECT_LE(static_cast<int64_t>(coarse.triangles.size()), budget.max_triangles);
  EXPECT_GT(static_cast<int64_t>(coarse.triangles.size()), budget.max_triangles / 2);
  const MeshTopology topology = AnalyseTopology(coarse);
  EXPECT_TRUE(topology.IsClosedManifold());
  EXPECT_EQ(topology.components, 1);
  EXPECT_TRUE(outwards(coarse));
  // A budget also caps the splitting.
  SurfaceMeshOptions both = split;
  both.max_triangles = static_cast<int64_t>(plain.triangles.size());
  EXPECT_LE(static_cast<int64_t>(MeshSolidVoxels(volume, both).triangles.size()),
            both.max_triangles);
}

TEST(SurfaceMesh, AnEmptyVolumeGivesAnEmptyMeshAndAValidEmptyPly) {
  const Volume volume = MakeVolume(8, [](const Eigen::Vector3d&) { return false; });
  const TriangleMesh mesh = MeshSolidVoxels(volume, SurfaceMeshOptions());
  EXPECT_TRUE(mesh.empty());
  EXPECT_TRUE(mesh.vertices.empty());
  const std::string folder = testing::MakeTemporaryDirectory("surface_mesh_empty");
  WriteMeshPly(mesh, folder + "/mesh.ply");
  const std::string bytes = testing::ReadFileBytes(folder + "/mesh.ply");
  EXPECT_EQ(bytes.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(bytes.find("element vertex 0\n"), std::string::npos);
  EXPECT_NE(bytes.find("element face 0\n"), std::string::npos);
  EXPECT_EQ(bytes.substr(bytes.size() - 11), "end_header\n");
  std::filesystem::remove_all(folder);
}

TEST(SurfaceMesh, OptionsOutOfRangeAreRefused) {
  std::string reason;
  SurfaceMeshOptions options;
  EXPECT_TRUE(options.IsValid(&reason));
  options.smoothing_pass_band = 0.0;
  EXPECT_FALSE(options.IsValid(&reason));
  options = SurfaceMeshOptions();
  options.max_triangles = 2;
  EXPECT_FALSE(options.IsValid(&reason));
  options = SurfaceMeshOptions();
  options.max_edge_length = -1.0;
  EXPECT_FALSE(options.IsValid(&reason));
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
