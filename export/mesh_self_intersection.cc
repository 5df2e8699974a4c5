#include "export/mesh_self_intersection.h"

#include <algorithm>
#include <chrono>
#include <sstream>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/intersections.h>

namespace raycarve {
namespace exporter {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Segment = Kernel::Segment_3;
using Triangle = Kernel::Triangle_3;

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

// A triangle's bounding box.
struct TriangleBox {
  Eigen::Vector3f low, high;
  int triangle;
};

bool Overlap(const TriangleBox& a, const TriangleBox& b) {
  return (a.low.array() <= b.high.array()).all() && (b.low.array() <= a.high.array()).all();
}

}  // namespace

std::vector<std::pair<int, int>> FindSelfIntersections(const TriangleMesh& mesh,
                                                       const std::vector<uint8_t>* check) {
  std::vector<TriangleBox> boxes;
  boxes.reserve(mesh.triangles.size());
  std::vector<float> extents;
  for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t) {
    const Eigen::Vector3i& triangle = mesh.triangles[t];
    if (Degenerate(triangle)) continue;
    const Eigen::Vector3f& p0 = mesh.vertices[triangle[0]];
    const Eigen::Vector3f& p1 = mesh.vertices[triangle[1]];
    const Eigen::Vector3f& p2 = mesh.vertices[triangle[2]];
    if (!p0.allFinite() || !p1.allFinite() || !p2.allFinite()) continue;
    TriangleBox box{p0.cwiseMin(p1).cwiseMin(p2), p0.cwiseMax(p1).cwiseMax(p2), t};
    boxes.push_back(box);
    extents.push_back((box.high - box.low).maxCoeff());
  }
  std::vector<std::pair<int, int>> pairs;
  if (boxes.size() < 2) return pairs;
  // Candidates share a cell of a uniform grid whose cells are twice the 90th percentile of the
  // triangles' extents (a triangle then touches at most 8 cells, mostly 1), grown until the grid
  // has at most about a cell per triangle.
  std::nth_element(extents.begin(), extents.begin() + extents.size() * 9 / 10, extents.end());
  Eigen::Vector3f low = boxes[0].low, high = boxes[0].high;
  for (const TriangleBox& box : boxes) {
    low = low.cwiseMin(box.low);
    high = high.cwiseMax(box.high);
  }
  double cell = std::max<double>(2.0 * extents[extents.size() * 9 / 10],
                                 1e-6 * std::max(1e-30f, (high - low).maxCoeff()));
  const auto cells_along = [&](int axis) {
    return static_cast<int64_t>((high[axis] - low[axis]) / cell) + 1;
  };
  while (cells_along(0) * cells_along(1) * cells_along(2) > 4 * static_cast<int64_t>(boxes.size())) {
    cell *= 1.5;
  }
  const int64_t nx = cells_along(0), ny = cells_along(1);
  const auto cell_of = [&](float value, int axis) {
    return static_cast<int64_t>((value - low[axis]) / cell);
  };
  // (cell, box) for every cell each box touches, grouped by cell.
  std::vector<std::pair<int64_t, int>> entries;
  entries.reserve(boxes.size() * 2);
  for (int i = 0; i < static_cast<int>(boxes.size()); ++i) {
    const TriangleBox& box = boxes[i];
    for (int64_t z = cell_of(box.low.z(), 2); z <= cell_of(box.high.z(), 2); ++z) {
      for (int64_t y = cell_of(box.low.y(), 1); y <= cell_of(box.high.y(), 1); ++y) {
        for (int64_t x = cell_of(box.low.x(), 0); x <= cell_of(box.high.x(), 0); ++x) {
          entries.emplace_back((z * ny + y) * nx + x, i);
        }
      }
    }
  }
  std::sort(entries.begin(), entries.end());
  for (size_t begin = 0; begin < entries.size();) {
    size_t end = begin;
    while (end < entries.size() && entries[end].first == entries[begin].first) ++end;
    const int64_t here = entries[begin].first;
    for (size_t i = begin; i < end; ++i) {
      const TriangleBox& a = boxes[entries[i].second];
      for (size_t j = i + 1; j < end; ++j) {
        const TriangleBox& b = boxes[entries[j].second];
        if (check != nullptr && !(*check)[a.triangle] && !(*check)[b.triangle]) continue;
        if (!Overlap(a, b)) continue;
        // Tested once: in the first cell the two boxes share.
        const Eigen::Vector3f shared = a.low.cwiseMax(b.low);
        if ((cell_of(shared.z(), 2) * ny + cell_of(shared.y(), 1)) * nx + cell_of(shared.x(), 0) !=
            here) {
          continue;
        }
        if (Intersect(mesh, a.triangle, b.triangle)) {
          pairs.emplace_back(std::min(a.triangle, b.triangle), std::max(a.triangle, b.triangle));
        }
      }
    }
    begin = end;
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
