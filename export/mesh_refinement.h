#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "calib/calibrated_view.h"
#include "export/surface_mesh.h"

namespace raycarve {
namespace exporter {

// Moves a mesh's vertices along their normals to where the photos agree best.
//
// Voxel colouring keeps every voxel whose photos agree to within the threshold, so its surface lies
// up to a voxel or so outside the true one (in front of it as the photos see it), and the
// iso-surface adds half a voxel more. Each pass: every vertex that two or more photos see (as
// FindVertexSightings says), two of which tell its offsets apart (over the search range the points
// they sample on the surface part by at least a pixel's footprint there: not so for photos that all
// look from one side at a grazing angle; where none do, it moves half a voxel in once, the
// iso-surface's offset on average), tries offsets along its normal within +-search_range, and
// at each it compares small patches (the point and 4 points around it on the tangent plane) across
// those photos: the cost is the mean over photos and patch samples of the squared RGB distance to
// the photos' mean. The vertex's offset is the cheapest one where that is clearly better than
// staying (below `min_gain` x the cost of staying), else 0; offsets are then averaged over each
// vertex's neighbours (smoothing passes) before the vertices move, and normals are recomputed.
// Passes go on until one moves the mesh's vertices by less than `converged_offset` on average (each
// pass moves a vertex by at most `search_range`, and the surface the carve leaves can lie several
// voxels out where the photos agree above it, the more voxels the finer the grid), or until
// `passes` have run.
struct MeshRefinementOptions {
  int passes = 4;                   // search and move passes at most
  double converged_offset = 0.0;    // world units; a pass moving the vertices less on average is the last (0: run every pass)
  double search_range = 0.0;        // world units either side; must be > 0 (about a voxel)
  int steps_per_side = 4;           // offsets tried on each side of 0
  double patch_radius = 0.0;        // world units from the centre to the 4 tangent samples (> 0)
  double depth_tolerance = 0.0;     // for FindVertexSightings (> 0)
  double voxel_size = 0.0;          // vertices within a voxel of a mask's edge only move out (> 0)
  int min_views = 2;                // photos needed to judge a vertex
  double min_gain = 0.8;            // an offset must cost below this share of staying
  int smoothing_passes = 3;         // neighbour averaging of the offsets
  int max_views = 16;               // at most this many photos judge a vertex: the best-facing
  int num_threads = 0;              // 0: every core (the result does not depend on it)

  bool IsValid(std::string* reason) const;
};

struct MeshRefinementSummary {
  int64_t vertices = 0;
  int64_t judged = 0;     // seen by min_views photos that tell its offsets apart, in the last pass
  int64_t unresolved = 0;  // seen by min_views photos, no two of which tell them apart (first pass)
  int64_t moved = 0;      // given a non-zero offset before smoothing, in the last pass
  int passes = 0;         // passes run
  double search_range = 0.0;  // world units either side, as asked
  double last_mean_abs_offset = 0.0;  // over all vertices, in the last pass
  double mean_offset = 0.0;  // signed, along the normal (negative: inwards), over all passes
  double mean_abs_offset = 0.0;
  double seconds = 0.0;
  // Per vertex, from the last pass: how firmly the photos place it along its normal, 0-1. The
  // cost at an offset is a mean of `m` squared colour deviations, so by chance alone it varies
  // by about cost * sqrt(2 / m) (a sample variance's standard error). z is the margin by which
  // the best offset's cost lies below the mean cost over the offsets tried, in those units:
  // pinned = (z - 1) / 2 clamped to [0, 1], so a minimum within one standard error is noise (0)
  // and one three or more below is the photos' (1); then averaged over neighbours as the
  // offsets are (`smoothing_passes`), so that it changes smoothly over the mesh. Plain surfaces
  // (the same colour at every offset) and vertices fewer than min_views photos see get 0.
  std::vector<float> pinned;
  double mean_pinned = 0.0;
  std::string Summary() const;
};

MeshRefinementSummary RefineMeshFromPhotos(const std::vector<CalibratedView>& views,
                                           const MeshRefinementOptions& options,
                                           TriangleMesh* mesh);

}  // namespace exporter
}  // namespace raycarve
