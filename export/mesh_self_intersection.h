#pragma once
// Whether a mesh folds through itself, and undoing the moves that made it fold. CGAL stays
// inside the .cc file.

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "export/surface_mesh.h"

namespace raycarve {
namespace exporter {

// The pairs of triangles (indices, first < second) that intersect anywhere but in what they
// share: two triangles with no common vertex that touch at all; two with one common vertex that
// meet elsewhere too (an edge of one through the other). Two with a common edge are not tested
// (they meet only along it unless they lie folded flat onto each other). Candidates are the
// pairs whose bounding boxes overlap in a cell of a uniform grid, tests come from CGAL's exact
// predicates, run on up to `num_threads` threads (the answer is the same for any count).
// Triangles with a repeated vertex are left out (AnalyseTopology counts them). Sorted. With
// `check` (one flag per triangle), only the pairs with a flagged triangle, found in the grid's
// cells that flagged triangles touch.
std::vector<std::pair<int, int>> FindSelfIntersections(const TriangleMesh& mesh,
                                                       const std::vector<uint8_t>* check = nullptr,
                                                       int num_threads = 1);

// How UndoSelfIntersections went.
struct SelfIntersectionRepair {
  int64_t pairs_before = 0;        // FindSelfIntersections on the mesh given
  int64_t pairs_after = 0;         // ... on the mesh returned
  int64_t vertices_moved_back = 0;  // distinct vertices moved towards their safe position
  int rounds = 0;
  double seconds = 0.0;
  std::string Summary() const;
};

// How UndoSelfIntersections works.
struct UndoOptions {
  // A flag per vertex: those that moved since the mesh last had no self-intersections. Only pairs
  // with a triangle that has a moved corner are then looked for, pairs_before included: the rest
  // of the mesh is taken to be as clean as it was. Null: the whole mesh is searched.
  const std::vector<uint8_t>* moved = nullptr;
  int num_threads = 1;  // the answer is the same for any count
  // Told a line (pairs left, rounds, seconds) when a round ends 5 seconds or more after the
  // undo began or the last line; unset: nothing told.
  std::function<void(const std::string&)> progress;
};

// Undoes the moves that made `mesh` fold through itself: while triangles intersect, the vertices
// of every intersecting triangle and their neighbours move back towards their positions in
// `safe` (the same vertices and triangles at an earlier stage, without self-intersections, such
// as the iso-surface before it was smoothed and refined), an eighth of the way in the first
// rounds, then a quarter, then half, then all the way, for at most 50 rounds.
// Vertices of triangles that do not intersect stay where they are. When `safe` itself
// intersects, what it shares with the mesh cannot be undone: pairs_after says so. Normals are
// recomputed for the vertices moved.
SelfIntersectionRepair UndoSelfIntersections(const std::vector<Eigen::Vector3f>& safe,
                                             TriangleMesh* mesh,
                                             const UndoOptions& options = {});

}  // namespace exporter
}  // namespace raycarve
