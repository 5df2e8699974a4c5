#include "export/mesh_self_intersection.h"

#include <algorithm>
#include <chrono>
#include <initializer_list>
#include <mutex>
#include <sstream>

#include <glog/logging.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/intersections.h>

#include "export/parallel_ranges.h"

namespace raycarve {
namespace exporter {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Segment = Kernel::Segment_3;
using Triangle = Kernel::Triangle_3;

Point ToPoint(const Eigen::Vector3f& p) { return Point(p.x(), p.y(), p.z()); }

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

bool Degenerate(const Eigen::Vector3i& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

// A flag per triangle: whether any of its corners is flagged in `vertices`.
std::vector<uint8_t> TrianglesWithFlaggedCorner(const TriangleMesh& mesh,
                                                const std::vector<uint8_t>& vertices) {
  std::vector<uint8_t> triangles(mesh.triangles.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Eigen::Vector3i& triangle = mesh.triangles[t];
    triangles[t] = vertices[triangle[0]] | vertices[triangle[1]] | vertices[triangle[2]];
  }
  return triangles;
}

// A triangle's corners in double (exact from float) and its plane's normal.
struct Corners {
  Eigen::Vector3d p[3];
  Eigen::Vector3d normal;
  double scale = 0.0;  // |p1 - p0| |p2 - p0|: the normal's length for a right angle
};

Corners CornersOf(const TriangleMesh& mesh, const Eigen::Vector3i& t) {
  Corners c;
  for (int i = 0; i < 3; ++i) c.p[i] = mesh.vertices[t[i]].cast<double>();
  const Eigen::Vector3d e1 = c.p[1] - c.p[0], e2 = c.p[2] - c.p[0];
  c.normal = e1.cross(e2);
  c.scale = e1.norm() * e2.norm();
  return c;
}

// Quick answers in double before CGAL's exact predicates, taken only where double's rounding
// (relative errors near 1e-16) cannot change them: a margin of 1e-10 of the quantities' scale.
constexpr double kCertain = 1e-10;

// Whether the triangle is surely not degenerate (its normal far from zero).
bool SurelyProper(const Corners& c) { return c.normal.norm() > kCertain * c.scale; }

// +1 or -1 where `point` lies surely on that side of the plane of `c` (SurelyProper), else 0.
int SideOf(const Corners& c, const Eigen::Vector3d& point) {
  const Eigen::Vector3d offset = point - c.p[0];
  const double distance = c.normal.dot(offset);
  const double bound = kCertain * c.scale * offset.norm();
  return distance > bound ? 1 : distance < -bound ? -1 : 0;
}

// Whether all of `points` lie surely on one side of the plane of `c`.
bool SurelyOneSide(const Corners& c, std::initializer_list<const Eigen::Vector3d*> points) {
  int first = 0;
  for (const Eigen::Vector3d* point : points) {
    const int side = SideOf(c, *point);
    if (side == 0 || (first != 0 && side != first)) return false;
    first = side;
  }
  return true;
}

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
  const Corners ca = CornersOf(mesh, ta), cb = CornersOf(mesh, tb);
  const bool proper = SurelyProper(ca) && SurelyProper(cb);
  const Triangle triangle_a(point(ta[0]), point(ta[1]), point(ta[2]));
  const Triangle triangle_b(point(tb[0]), point(tb[1]), point(tb[2]));
  if (!proper && (triangle_a.is_degenerate() || triangle_b.is_degenerate())) return false;
  if (shared == 0) {
    // Apart where one lies wholly on one side of the other's plane.
    if (SurelyOneSide(ca, {&cb.p[0], &cb.p[1], &cb.p[2]}) ||
        SurelyOneSide(cb, {&ca.p[0], &ca.p[1], &ca.p[2]})) {
      return false;
    }
    return CGAL::do_intersect(triangle_a, triangle_b);
  }
  // One common vertex: they meet elsewhere when the edge opposite it in one triangle crosses
  // the other (any other intersection of two triangles includes such a crossing); an edge wholly
  // on one side of the other's plane does not.
  const int a1 = (shared_in_a + 1) % 3, a2 = (shared_in_a + 2) % 3;
  const int b1 = (shared_in_b + 1) % 3, b2 = (shared_in_b + 2) % 3;
  if (!SurelyOneSide(cb, {&ca.p[a1], &ca.p[a2]}) &&
      CGAL::do_intersect(Segment(point(ta[a1]), point(ta[a2])), triangle_b)) {
    return true;
  }
  return !SurelyOneSide(ca, {&cb.p[b1], &cb.p[b2]}) &&
         CGAL::do_intersect(Segment(point(tb[b1]), point(tb[b2])), triangle_a);
}

}  // namespace

namespace {

// An axis-aligned box.
struct Box {
  Eigen::Vector3f low, high;
};

bool Overlap(const Box& a, const Box& b) {
  return (a.low.array() <= b.high.array()).all() && (b.low.array() <= a.high.array()).all();
}

// The triangles of a mesh in the cells of a uniform grid, for finding the pairs whose boxes
// overlap. Each triangle is filed under the box that holds it where it is and, with `towards`,
// also at the corners' positions there: a vertex that moves only towards its position in
// `towards` (UndoSelfIntersections) keeps its triangle inside that box, so the grid, built once,
// answers for every step of the way.
class TriangleGrid {
 public:
  TriangleGrid(const TriangleMesh& mesh, const std::vector<Eigen::Vector3f>* towards)
      : mesh_(mesh), towards_(towards) {
    const int count = static_cast<int>(mesh.triangles.size());
    filed_.assign(count, 0);
    std::vector<float> extents;
    extents.reserve(count);
    bool any = false;
    Box all;
    swept_.resize(count);
    for (int t = 0; t < count; ++t) {
      if (!Usable(t)) continue;
      filed_[t] = 1;
      swept_[t] = SweptBox(t);
      const Box& box = swept_[t];
      const Box now = Current(t);
      extents.push_back((now.high - now.low).maxCoeff());
      all = any ? Box{all.low.cwiseMin(box.low), all.high.cwiseMax(box.high)} : box;
      any = true;
    }
    filed_count_ = static_cast<int64_t>(extents.size());
    if (filed_count_ < 2) return;
    low_ = all.low;
    // Cells twice the 90th percentile of the triangles' extents where they are (a triangle then
    // touches at most 8 cells, mostly 1, unless it moves far), grown until the grid has at most
    // about four cells per triangle.
    std::nth_element(extents.begin(), extents.begin() + extents.size() * 9 / 10, extents.end());
    cell_ = std::max<double>(2.0 * extents[extents.size() * 9 / 10],
                             1e-6 * std::max(1e-30f, (all.high - all.low).maxCoeff()));
    const auto along = [&](int axis) {
      return static_cast<int64_t>((all.high[axis] - all.low[axis]) / cell_) + 1;
    };
    while (along(0) * along(1) * along(2) > 4 * filed_count_) cell_ *= 1.5;
    nx_ = along(0);
    ny_ = along(1);
    nz_ = along(2);
    // Counting sort of (cell, triangle) by cell: starts_[c] .. starts_[c + 1] in members_.
    starts_.assign(static_cast<size_t>(nx_ * ny_ * nz_) + 1, 0);
    for (int t = 0; t < count; ++t) {
      if (filed_[t]) ForEachCell(swept_[t], [&](int64_t c) { ++starts_[c + 1]; });
    }
    uint64_t total = 0;
    for (size_t c = 1; c < starts_.size(); ++c) {
      total += starts_[c];
      CHECK_LT(total, uint64_t{1} << 32) << "too many triangles for one grid";
      starts_[c] = static_cast<uint32_t>(total);
    }
    members_.resize(starts_.back());
    std::vector<uint32_t> next(starts_.begin(), starts_.end() - 1);
    for (int t = 0; t < count; ++t) {
      if (filed_[t]) ForEachCell(swept_[t], [&](int64_t c) { members_[next[c]++] = t; });
    }
  }

  // The intersecting pairs at the mesh's present positions (see FindSelfIntersections).
  std::vector<std::pair<int, int>> Find(const std::vector<uint8_t>* check, int threads) const {
    std::vector<std::pair<int, int>> pairs;
    if (filed_count_ < 2) return pairs;
    std::mutex joined;
    const auto join = [&](std::vector<std::pair<int, int>>* found) {
      const std::lock_guard<std::mutex> lock(joined);
      pairs.insert(pairs.end(), found->begin(), found->end());
    };
    if (check == nullptr) {
      // Every pair in every cell.
      ParallelRanges(starts_.size() - 1, threads, 1 << 16, [&](size_t first, size_t last) {
        std::vector<std::pair<int, int>> found;
        for (size_t c = first; c < last; ++c) {
          for (uint32_t i = starts_[c]; i < starts_[c + 1]; ++i) {
            const int a = members_[i];
            const Box now_a = Current(a);
            for (uint32_t j = i + 1; j < starts_[c + 1]; ++j) {
              Test(a, now_a, members_[j], static_cast<int64_t>(c), &found);
            }
          }
        }
        join(&found);
      });
    } else {
      // Each flagged triangle against the others in its cells; two flagged ones once.
      std::vector<int> flagged;
      for (int t = 0; t < static_cast<int>(filed_.size()); ++t) {
        if (filed_[t] && (*check)[t]) flagged.push_back(t);
      }
      ParallelRanges(flagged.size(), threads, 4096, [&](size_t first, size_t last) {
        std::vector<std::pair<int, int>> found;
        for (size_t k = first; k < last; ++k) {
          const int a = flagged[k];
          // A triangle whose box overlaps a's now is filed in a cell that a's box now touches.
          const Box now = Current(a);
          ForEachCell(now, [&](int64_t c) {
            for (uint32_t i = starts_[c]; i < starts_[c + 1]; ++i) {
              const int b = members_[i];
              if (b == a || ((*check)[b] && b < a)) continue;
              Test(a, now, b, c, &found);
            }
          });
        }
        join(&found);
      });
    }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    return pairs;
  }

 private:
  bool Usable(int t) const {
    const Eigen::Vector3i& triangle = mesh_.triangles[t];
    if (Degenerate(triangle)) return false;
    for (int corner = 0; corner < 3; ++corner) {
      if (!mesh_.vertices[triangle[corner]].allFinite()) return false;
      if (towards_ != nullptr && !(*towards_)[triangle[corner]].allFinite()) return false;
    }
    return true;
  }

  Box Current(int t) const {
    const Eigen::Vector3i& triangle = mesh_.triangles[t];
    const Eigen::Vector3f& p0 = mesh_.vertices[triangle[0]];
    const Eigen::Vector3f& p1 = mesh_.vertices[triangle[1]];
    const Eigen::Vector3f& p2 = mesh_.vertices[triangle[2]];
    return {p0.cwiseMin(p1).cwiseMin(p2), p0.cwiseMax(p1).cwiseMax(p2)};
  }

  // Where the triangle can be: its box now and, with towards_, there, widened by a margin for
  // the rounding of the steps between (a step's float sum can land an ulp past its end).
  Box SweptBox(int t) const {
    Box box = Current(t);
    if (towards_ == nullptr) return box;
    const Eigen::Vector3i& triangle = mesh_.triangles[t];
    for (int corner = 0; corner < 3; ++corner) {
      box.low = box.low.cwiseMin((*towards_)[triangle[corner]]);
      box.high = box.high.cwiseMax((*towards_)[triangle[corner]]);
    }
    const float margin =
        1e-5f * (1.0f + std::max(box.low.cwiseAbs().maxCoeff(), box.high.cwiseAbs().maxCoeff()));
    box.low.array() -= margin;
    box.high.array() += margin;
    return box;
  }

  // Clamped to the grid: a box now lies inside the one filed (up to the margin).
  int64_t CellOf(float value, int axis) const {
    const int64_t along = axis == 0 ? nx_ : axis == 1 ? ny_ : nz_;
    return std::clamp<int64_t>(static_cast<int64_t>((value - low_[axis]) / cell_), 0, along - 1);
  }
  int64_t CellAt(const Eigen::Vector3f& point) const {
    return (CellOf(point.z(), 2) * ny_ + CellOf(point.y(), 1)) * nx_ + CellOf(point.x(), 0);
  }

  template <typename Visit>
  void ForEachCell(const Box& box, const Visit& visit) const {
    for (int64_t z = CellOf(box.low.z(), 2); z <= CellOf(box.high.z(), 2); ++z) {
      for (int64_t y = CellOf(box.low.y(), 1); y <= CellOf(box.high.y(), 1); ++y) {
        for (int64_t x = CellOf(box.low.x(), 0); x <= CellOf(box.high.x(), 0); ++x) {
          visit((z * ny_ + y) * nx_ + x);
        }
      }
    }
  }

  // Tests triangles a (its box now `now_a`) and b met in cell `here`: only where their boxes
  // overlap now, and once, in the cell of the overlap's lowest corner (both are filed there: it
  // lies in b's box now, so in the box it is filed under, and a visits the cells its box now
  // touches).
  void Test(int a, const Box& now_a, int b, int64_t here,
            std::vector<std::pair<int, int>>* found) const {
    if (!Overlap(swept_[a], swept_[b])) return;
    const Box now_b = Current(b);
    if (!Overlap(now_a, now_b)) return;
    if (CellAt(now_a.low.cwiseMax(now_b.low)) != here) return;
    if (Intersect(mesh_, a, b)) found->emplace_back(std::min(a, b), std::max(a, b));
  }

  const TriangleMesh& mesh_;
  const std::vector<Eigen::Vector3f>* towards_;
  std::vector<uint8_t> filed_;  // per triangle: usable, so in the grid
  std::vector<Box> swept_;      // per triangle filed: where it can be (SweptBox)
  int64_t filed_count_ = 0;
  Eigen::Vector3f low_ = Eigen::Vector3f::Zero();
  double cell_ = 1.0;
  int64_t nx_ = 1, ny_ = 1, nz_ = 1;
  std::vector<uint32_t> starts_;  // per cell, and one past the last
  std::vector<int> members_;
};

}  // namespace

std::vector<std::pair<int, int>> FindSelfIntersections(const TriangleMesh& mesh,
                                                       const std::vector<uint8_t>* check,
                                                       int num_threads) {
  return TriangleGrid(mesh, nullptr).Find(check, num_threads);
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
                                             TriangleMesh* mesh,
                                             const UndoOptions& options) {
  const std::vector<uint8_t>* moved = options.moved;
  const int num_threads = options.num_threads;
  const auto start = std::chrono::steady_clock::now();
  SelfIntersectionRepair repair;
  // Small steps back keep most of what the refinement found (an eighth of the way in the first
  // rounds, then a quarter, then half); then all the way.
  constexpr int kEighthRounds = 8;
  constexpr int kQuarterRounds = 12;
  constexpr int kHalfwayRounds = 15;
  constexpr int kMaxRounds = 50;
  std::vector<uint8_t> moved_triangles;
  if (moved != nullptr) {
    CHECK_EQ(moved->size(), mesh->vertices.size());
    moved_triangles = TrianglesWithFlaggedCorner(*mesh, *moved);
  }
  // Vertices only move towards `safe`: one grid serves every round.
  const bool can_undo = safe.size() == mesh->vertices.size();
  const TriangleGrid grid(*mesh, can_undo ? &safe : nullptr);
  std::vector<std::pair<int, int>> pairs =
      grid.Find(moved != nullptr ? &moved_triangles : nullptr, num_threads);
  repair.pairs_before = static_cast<int64_t>(pairs.size());
  constexpr double kTellEverySeconds = 5.0;
  double last_told = 0.0;
  if (!pairs.empty() && can_undo) {
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
      moved_triangles = TrianglesWithFlaggedCorner(*mesh, involved);
      pairs = grid.Find(&moved_triangles, num_threads);
      const double seconds = SecondsSince(start);
      if (options.progress && seconds >= last_told + kTellEverySeconds) {
        std::ostringstream line;
        line.precision(3);
        line << repair.pairs_before << " pairs of triangles folded through each other: "
             << pairs.size() << " left after " << repair.rounds << " rounds of moving their "
             << "vertices back, " << seconds << " s ...";
        options.progress(line.str());
        last_told = seconds;
      }
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
  repair.seconds = SecondsSince(start);
  return repair;
}

}  // namespace exporter
}  // namespace raycarve
