#include "export/mesh_self_intersection.h"

#include <algorithm>
#include <chrono>
#include <sstream>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/intersections.h>

namespace raycarve {
namespace exporter {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Segment = Kernel::Segment_3;
using Triangle = Kernel::Triangle_3;
using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, int>;

Point ToPoint(const Eigen::Vector3f& p) { return Point(p.x(), p.y(), p.z()); }

bool Degenerate(const Eigen::Vector3i& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

// Whether triangles a and b (indices into mesh) intersect beyond what they share.
bool Intersect(const TriangleMesh& mesh, int a, int b) {
  const Eigen::Vector3i& ta = mesh.triangles[a];
  const Eigen::Vector3i& tb = mesh.triangles[b];
  int shared = 0, shared_in_a = -1, shared_in_b = -1;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (ta[i] == tb[j]) {
        ++shared;
        shared_in_a = i;
        shared_in_b = j;
      }
    }
  }
  // Neighbours across an edge are most of the candidates: answered before any geometry.
  if (shared >= 2) return false;
  const auto point = [&](int vertex) { return ToPoint(mesh.vertices[vertex]); };
  const Triangle triangle_a(point(ta[0]), point(ta[1]), point(ta[2]));
  const Triangle triangle_b(point(tb[0]), point(tb[1]), point(tb[2]));
  if (triangle_a.is_degenerate() || triangle_b.is_degenerate()) return false;
  if (shared == 0) return CGAL::do_intersect(triangle_a, triangle_b);
  // One common vertex: they meet elsewhere when the edge opposite it in one triangle crosses
  // the other (any other intersection of two triangles includes such a crossing).
  const Segment opposite_a(point(ta[(shared_in_a + 1) % 3]), point(ta[(shared_in_a + 2) % 3]));
  const Segment opposite_b(point(tb[(shared_in_b + 1) % 3]), point(tb[(shared_in_b + 2) % 3]));
  return CGAL::do_intersect(opposite_a, triangle_b) || CGAL::do_intersect(opposite_b, triangle_a);
}

}  // namespace

namespace {

// The triangle's bounding box, false for a degenerate or non-finite triangle.
bool TriangleBox(const TriangleMesh& mesh, int t, Box* box) {
  const Eigen::Vector3i& triangle = mesh.triangles[t];
  if (Degenerate(triangle)) return false;
  const Eigen::Vector3f& p0 = mesh.vertices[triangle[0]];
  const Eigen::Vector3f& p1 = mesh.vertices[triangle[1]];
  const Eigen::Vector3f& p2 = mesh.vertices[triangle[2]];
  if (!p0.allFinite() || !p1.allFinite() || !p2.allFinite()) return false;
  const Eigen::Vector3f low = p0.cwiseMin(p1).cwiseMin(p2);
  const Eigen::Vector3f high = p0.cwiseMax(p1).cwiseMax(p2);
  *box = Box(CGAL::Bbox_3(low.x(), low.y(), low.z(), high.x(), high.y(), high.z()), t);
  return true;
}

}  // namespace

std::vector<std::pair<int, int>> FindSelfIntersections(const TriangleMesh& mesh,
                                                       const std::vector<uint8_t>* check) {
  std::vector<Box> boxes, checked;
  boxes.reserve(mesh.triangles.size());
  for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t) {
    Box box;
    if (!TriangleBox(mesh, t, &box)) continue;
    boxes.push_back(box);
    if (check != nullptr && (*check)[t]) checked.push_back(box);
  }
  std::vector<std::pair<int, int>> pairs;
  const auto test = [&](const Box& a, const Box& b) {
    if (a.info() != b.info() && Intersect(mesh, a.info(), b.info())) {
      pairs.emplace_back(std::min(a.info(), b.info()), std::max(a.info(), b.info()));
    }
  };
  if (check == nullptr) {
    CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), test);
  } else if (!checked.empty()) {
    // Only the boxes near a checked one can meet it: those touching a cell of a coarse grid
    // (kNearCells a side over the mesh's box) that a checked box touches. When few triangles are
    // checked this leaves most of the mesh out of the search.
    constexpr int kNearCells = 64;
    CGAL::Bbox_3 whole;
    for (const Box& box : boxes) whole += box.bbox();
    const double low[3] = {whole.xmin(), whole.ymin(), whole.zmin()};
    double cell[3];
    for (int axis = 0; axis < 3; ++axis) {
      cell[axis] = std::max((whole.max(axis) - whole.min(axis)) / kNearCells, 1e-30);
    }
    const auto cell_range = [&](const Box& box, int axis, int* from, int* to) {
      *from = std::clamp(static_cast<int>((box.min_coord(axis) - low[axis]) / cell[axis]), 0, kNearCells - 1);
      *to = std::clamp(static_cast<int>((box.max_coord(axis) - low[axis]) / cell[axis]), 0, kNearCells - 1);
    };
    std::vector<uint8_t> marked(kNearCells * kNearCells * kNearCells, 0);
    int from[3], to[3];
    for (const Box& box : checked) {
      for (int axis = 0; axis < 3; ++axis) cell_range(box, axis, &from[axis], &to[axis]);
      for (int z = from[2]; z <= to[2]; ++z) {
        for (int y = from[1]; y <= to[1]; ++y) {
          for (int x = from[0]; x <= to[0]; ++x) marked[(z * kNearCells + y) * kNearCells + x] = 1;
        }
      }
    }
    std::vector<Box> near;
    for (const Box& box : boxes) {
      for (int axis = 0; axis < 3; ++axis) cell_range(box, axis, &from[axis], &to[axis]);
      bool touches = false;
      for (int z = from[2]; z <= to[2] && !touches; ++z) {
        for (int y = from[1]; y <= to[1] && !touches; ++y) {
          for (int x = from[0]; x <= to[0] && !touches; ++x) {
            touches = marked[(z * kNearCells + y) * kNearCells + x];
          }
        }
      }
      if (touches) near.push_back(box);
    }
    CGAL::box_intersection_d(checked.begin(), checked.end(), near.begin(), near.end(), test);
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

std::string SelfIntersectionRepair::Summary() const {
  std::ostringstream text;
  text.precision(3);
  if (pairs_before == 0) {
    text << "no self-intersecting triangles (checked in " << seconds << " s)";
    return text.str();
  }
  text << pairs_before << " pairs of triangles folded through each other; " << vertices_moved_back
       << " vertices moved back towards the unrefined surface in " << rounds << " rounds: "
       << pairs_after << " pairs left, in " << seconds << " s";
  return text.str();
}

SelfIntersectionRepair UndoSelfIntersections(const std::vector<Eigen::Vector3f>& safe,
                                             TriangleMesh* mesh) {
  const auto start = std::chrono::steady_clock::now();
  SelfIntersectionRepair repair;
  // Small steps back keep most of what the refinement found (an eighth of the way in the first
  // rounds, then a quarter, then half); then all the way.
  constexpr int kEighthRounds = 8;
  constexpr int kQuarterRounds = 12;
  constexpr int kHalfwayRounds = 15;
  constexpr int kMaxRounds = 50;
  std::vector<std::pair<int, int>> pairs = FindSelfIntersections(*mesh);
  repair.pairs_before = static_cast<int64_t>(pairs.size());
  if (!pairs.empty() && safe.size() == mesh->vertices.size()) {
    std::vector<uint8_t> ever_moved(mesh->vertices.size(), 0);
    while (!pairs.empty() && repair.rounds < kMaxRounds) {
      std::vector<uint8_t> involved(mesh->vertices.size(), 0);
      for (const auto& [a, b] : pairs) {
        for (const int t : {a, b}) {
          for (int corner = 0; corner < 3; ++corner) {
            involved[mesh->triangles[t][corner]] = 1;
          }
        }
      }
      const float back = repair.rounds < kEighthRounds    ? 0.125f
                         : repair.rounds < kQuarterRounds ? 0.25f
                         : repair.rounds < kHalfwayRounds ? 0.5f
                                                          : 1.0f;
      for (size_t v = 0; v < involved.size(); ++v) {
        if (!involved[v]) continue;
        mesh->vertices[v] += back * (safe[v] - mesh->vertices[v]);
        ever_moved[v] = 1;
      }
      ++repair.rounds;
      // Only triangles that moved can meet anew, and every pair found had its corners moved.
      std::vector<uint8_t> moved_triangles(mesh->triangles.size(), 0);
      for (size_t t = 0; t < mesh->triangles.size(); ++t) {
        const Eigen::Vector3i& triangle = mesh->triangles[t];
        moved_triangles[t] = involved[triangle[0]] | involved[triangle[1]] | involved[triangle[2]];
      }
      pairs = FindSelfIntersections(*mesh, &moved_triangles);
    }
    repair.vertices_moved_back = std::count(ever_moved.begin(), ever_moved.end(), 1);
    if (repair.vertices_moved_back > 0) {
      std::vector<Eigen::Vector3f> normals = mesh->normals;
      ComputeVertexNormals(mesh, NormalWeighting::kPerFace);
      if (normals.size() == mesh->normals.size()) {
        for (size_t v = 0; v < ever_moved.size(); ++v) {
          if (!ever_moved[v]) mesh->normals[v] = normals[v];
        }
      }
    }
  }
  repair.pairs_after = static_cast<int64_t>(pairs.size());
  repair.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return repair;
}

}  // namespace exporter
}  // namespace raycarve
