// Self-intersections against meshes whose answer is known by construction: disjoint and
// interpenetrating tetrahedra, triangles that share a vertex or an edge.
#include "export/mesh_self_intersection.h"

#include <algorithm>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "export/surface_mesh.h"

namespace raycarve {
namespace exporter {
namespace {

// A closed tetrahedron at `offset` (its four faces wound outwards), appended to `mesh`.
void AddTetrahedron(const Eigen::Vector3f& offset, TriangleMesh* mesh) {
  const int base = static_cast<int>(mesh->vertices.size());
  for (const Eigen::Vector3f& corner :
       {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(0, 1, 0),
        Eigen::Vector3f(0, 0, 1)}) {
    mesh->vertices.push_back(corner + offset);
  }
  for (const Eigen::Vector3i& face : {Eigen::Vector3i(0, 2, 1), Eigen::Vector3i(0, 1, 3),
                                      Eigen::Vector3i(0, 3, 2), Eigen::Vector3i(1, 2, 3)}) {
    mesh->triangles.push_back(face + Eigen::Vector3i::Constant(base));
  }
}

TEST(FindSelfIntersections, ApartTheyDoNotIntersectInterpenetratingTheyDo) {
  TriangleMesh apart;
  AddTetrahedron(Eigen::Vector3f::Zero(), &apart);
  AddTetrahedron(Eigen::Vector3f(2, 0, 0), &apart);
  EXPECT_TRUE(FindSelfIntersections(apart).empty());
  EXPECT_TRUE(AnalyseTopology(apart).IsClosedManifold());

  TriangleMesh through;
  AddTetrahedron(Eigen::Vector3f::Zero(), &through);
  AddTetrahedron(Eigen::Vector3f(0.2f, 0.2f, 0.2f), &through);
  const std::vector<std::pair<int, int>> pairs = FindSelfIntersections(through);
  ASSERT_FALSE(pairs.empty());
  for (const auto& [a, b] : pairs) {
    // Only faces of different tetrahedra meet; each pair once, in order.
    EXPECT_LT(a, 4);
    EXPECT_GE(b, 4);
  }
  // The second tetrahedron's corner (0.2, 0.2, 0.2) lies inside the first: the three faces
  // around it cross the first's slanted face (1, 2, 3), x + y + z = 1.
  for (const int face : {4, 5, 6}) {
    EXPECT_NE(std::find(pairs.begin(), pairs.end(), std::make_pair(3, face)), pairs.end()) << face;
  }
  const MeshTopology topology = AnalyseTopology(through);
  EXPECT_EQ(topology.boundary_edges, 0);
  EXPECT_EQ(topology.self_intersecting_pairs, static_cast<int64_t>(pairs.size()));
  EXPECT_FALSE(topology.IsClosedManifold());
  EXPECT_NE(topology.Faults().find("pairs of triangles through each other"), std::string::npos);
}

TEST(FindSelfIntersections, SharedCornersAndEdgesAreNotIntersectionsButACrossingEdgeIs) {
  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 1, 1}};
  // Two triangles sharing the edge 0-1, and one sharing only vertex 0, all apart elsewhere.
  mesh.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 4, 3}};
  EXPECT_TRUE(FindSelfIntersections(mesh).empty());
  // A triangle sharing vertex 0 whose opposite edge runs through triangle (0, 1, 2).
  mesh.vertices.push_back({0.3f, 0.3f, -0.5f});
  mesh.vertices.push_back({0.3f, 0.3f, 0.5f});
  mesh.triangles.push_back({0, 5, 6});
  const std::vector<std::pair<int, int>> pairs = FindSelfIntersections(mesh);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0], std::make_pair(0, 3));
}

TEST(FindSelfIntersections, FlaggedTrianglesAndThreadsFindTheSamePairsAsTheWholeSearch) {
  // Forty tetrahedra of sizes 0.3-1.5 scattered in a 6-unit cube: many overlap, many do not;
  // the grid's cells then hold triangles of different tetrahedra.
  TriangleMesh mesh;
  std::mt19937 random(7);
  std::uniform_real_distribution<float> place(0.0f, 6.0f), size(0.3f, 1.5f);
  for (int k = 0; k < 40; ++k) {
    const int base = static_cast<int>(mesh.vertices.size());
    AddTetrahedron(Eigen::Vector3f(place(random), place(random), place(random)), &mesh);
    const float scale = size(random);
    for (int v = base + 1; v < base + 4; ++v) {
      mesh.vertices[v] = mesh.vertices[base] + scale * (mesh.vertices[v] - mesh.vertices[base]);
    }
  }
  const std::vector<std::pair<int, int>> all = FindSelfIntersections(mesh);
  ASSERT_GT(all.size(), 20u);
  EXPECT_EQ(FindSelfIntersections(mesh, nullptr, 2), all);
  EXPECT_EQ(FindSelfIntersections(mesh, nullptr, 3), all);
  // Flag every fifth triangle: exactly the pairs with a flagged member.
  std::vector<uint8_t> check(mesh.triangles.size(), 0);
  for (size_t t = 0; t < check.size(); t += 5) check[t] = 1;
  std::vector<std::pair<int, int>> flagged;
  for (const auto& [a, b] : all) {
    if (check[a] || check[b]) flagged.emplace_back(a, b);
  }
  ASSERT_FALSE(flagged.empty());
  ASSERT_LT(flagged.size(), all.size());
  EXPECT_EQ(FindSelfIntersections(mesh, &check), flagged);
  EXPECT_EQ(FindSelfIntersections(mesh, &check, 2), flagged);
  const std::vector<uint8_t> none(mesh.triangles.size(), 0);
  EXPECT_TRUE(FindSelfIntersections(mesh, &none).empty());
}

TEST(UndoSelfIntersections, WhatWasPushedThroughGoesBackAndTheRestStays) {
  // Safe: three tetrahedra apart. Folded: the second pushed into the first; the third untouched.
  TriangleMesh safe;
  AddTetrahedron(Eigen::Vector3f::Zero(), &safe);
  AddTetrahedron(Eigen::Vector3f(2, 0, 0), &safe);
  AddTetrahedron(Eigen::Vector3f(0, 5, 0), &safe);
  ComputeVertexNormals(&safe);
  ASSERT_TRUE(FindSelfIntersections(safe).empty());
  TriangleMesh folded = safe;
  for (int v = 4; v < 8; ++v) folded.vertices[v] -= Eigen::Vector3f(1.8f, -0.2f, -0.2f);
  ASSERT_FALSE(FindSelfIntersections(folded).empty());
  EXPECT_FALSE(AnalyseTopology(folded).IsClosedManifold());
  const std::vector<Eigen::Vector3f> third(folded.vertices.begin() + 8, folded.vertices.end());

  const SelfIntersectionRepair repair = UndoSelfIntersections(safe.vertices, &folded);
  EXPECT_GT(repair.pairs_before, 0);
  EXPECT_EQ(repair.pairs_after, 0);
  EXPECT_TRUE(FindSelfIntersections(folded).empty());
  EXPECT_TRUE(AnalyseTopology(folded).IsClosedManifold());
  // The corners of the triangles that met; the first tetrahedron's were where they belong.
  EXPECT_GE(repair.vertices_moved_back, 4);
  EXPECT_LE(repair.vertices_moved_back, 8);
  for (int v = 0; v < 4; ++v) EXPECT_EQ(folded.vertices[v], safe.vertices[v]) << v;
  EXPECT_EQ(std::vector<Eigen::Vector3f>(folded.vertices.begin() + 8, folded.vertices.end()), third);
  // Back in steps, each along the way to its safe place: only as far as needed.
  EXPECT_GT(repair.rounds, 1);
  for (int v = 4; v < 8; ++v) {
    const Eigen::Vector3f from_safe = folded.vertices[v] - safe.vertices[v];
    EXPECT_LT(from_safe.norm(), 1.9f) << v;
    EXPECT_NEAR(from_safe.normalized().dot(Eigen::Vector3f(-1.8f, 0.2f, 0.2f).normalized()), 1.0f,
                1e-4f)
        << v;
  }
  EXPECT_NE(repair.Summary().find("0 pairs left"), std::string::npos) << repair.Summary();

  // Told which vertices moved (the second tetrahedron's), the repair looks only at their
  // triangles and does the same.
  TriangleMesh folded_again = safe;
  std::vector<uint8_t> moved(safe.vertices.size(), 0);
  for (int v = 4; v < 8; ++v) {
    folded_again.vertices[v] -= Eigen::Vector3f(1.8f, -0.2f, -0.2f);
    moved[v] = 1;
  }
  UndoOptions undo;
  undo.moved = &moved;
  undo.num_threads = 2;
  const SelfIntersectionRepair told = UndoSelfIntersections(safe.vertices, &folded_again, undo);
  EXPECT_EQ(told.pairs_before, repair.pairs_before);
  EXPECT_EQ(told.rounds, repair.rounds);
  EXPECT_EQ(told.vertices_moved_back, repair.vertices_moved_back);
  EXPECT_EQ(folded_again.vertices, folded.vertices);

  // A mesh without intersections is left exactly as it is.
  TriangleMesh clean = safe;
  clean.vertices[4].x() += 0.3f;
  const std::vector<Eigen::Vector3f> before = clean.vertices;
  const SelfIntersectionRepair none = UndoSelfIntersections(safe.vertices, &clean);
  EXPECT_EQ(none.pairs_before, 0);
  EXPECT_EQ(none.vertices_moved_back, 0);
  EXPECT_EQ(clean.vertices, before);
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
