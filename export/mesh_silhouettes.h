#pragma once

// The mesh held against the photos' masks: parts no mask needs go, and outlines that stand out
// beyond the masks are pulled in onto them.

#include <cstdint>
#include <string>
#include <vector>

#include "calib/calibrated_view.h"
#include "export/surface_mesh.h"

namespace raycarve {
namespace exporter {

// Without masks, parts below this share of the largest part's vertices are specks unless a
// sparse point lies on them: a piece of a hundredth of the model that no feature was matched on.
constexpr double kSpeckShare = 0.01;

struct MeshPartsSummary {
  int parts = 0;           // connected components before
  int removed = 0;
  int64_t removed_vertices = 0;
  int anchored = 0;        // kept for a sparse point alone (no two masks needed them)
  bool judged_by_masks = false;  // enough masked views; otherwise only specks were judged
  int masked_views = 0;
  int min_needing_views = 0;
  double seconds = 0.0;
  std::string Summary() const;
};

// Removes the parts (connected components) of `mesh` that fewer than `min_needing_views` masked
// views need. A view needs a part when at least half of the pixels the part covers in it lie on
// the view's object where no other part is drawn: nothing else in the model explains the mask
// there. A visual hull keeps phantoms, pieces of space that every photo sees within the object's
// silhouette (in front of it, behind it or, where poses are a little off, in the slivers where
// the masks overlap), and colour carving keeps those whose photos happen to agree; no mask needs
// them. A separate object is seen on its own in most photos. The largest part always stays;
// views without a mask count for nothing, and with fewer masked views than min_needing_views (or
// min_needing_views <= 0) nothing is removed. A part with a vertex within `anchor_radius` of one
// of `anchors` (reliable sparse points: features matched and triangulated across photos) that
// lies nearer to it than to the largest part stays too: a real piece of the object the masks fail to show on its own (holes in masks made from
// a backdrop the object shares colours with cut the model into pieces that overlap in every
// photo). Without enough masked views the masks cannot judge: then a part smaller than
// kSpeckShare of the largest (in vertices) with no anchor within `anchor_radius` is a speck the
// carve left floating, and goes; larger parts and parts holding a sparse point stay (with no
// anchors at all, nothing goes). Normals and colours follow the vertices.
MeshPartsSummary RemoveUnneededParts(const std::vector<CalibratedView>& views,
                                     int min_needing_views,
                                     const std::vector<Eigen::Vector3d>& anchors,
                                     double anchor_radius, int num_threads, TriangleMesh* mesh);

// Per vertex of `mesh`: 1 where it belongs to a speck as RemoveUnneededParts judges parts
// without masks (a part under kSpeckShare of the largest part's vertices with no anchor within
// `anchor_radius` nearer to it than to the largest part); all 0 without anchors or with one part.
std::vector<uint8_t> SpeckVertices(const TriangleMesh& mesh,
                                   const std::vector<Eigen::Vector3d>& anchors,
                                   double anchor_radius);

// Pulls the vertices of a closed mesh's outlines in along their normals onto the masks' edges.
//
// The carve keeps whole voxels and the iso-surface and its smoothing round them, so the mesh's
// outline stands up to a voxel beyond the masks' (the photos' colours cannot move it: refinement
// holds the rims). In each masked view the mesh is drawn (depth buffer, front faces); a vertex
// is on that view's outline when it is not hidden and lies within a pixel of a pixel the mesh
// does not cover and that connects to the image's border: the outer outline, not the rims of
// see-through holes inside it (a hole in a mask made from a backdrop the object shares colours
// with is a hole in the hull, and fitting its rim would widen it; on the composited backdrops
// that cost 0.3-0.4 dB held out; on the Middlebury temple leaving holes' rims alone costs
// 0.05). There the mask's signed distance (pixels, positive on the background, bilinear) and
// the speed at which a move along the normal carries the vertex's projection across the mask's
// edge give the move that puts it on the edge. Moves outwards count as 0: the masks'
// object pixels the mesh misses are the silhouette repair's, which works on the voxels. Per
// vertex the median over the views it is on the outline of is taken, so views whose masks
// disagree (poses a little off) cancel, limited to +-max_move, then spread over the neighbours
// as a weighted mean (the outline vertices' moves carried a few rings into the surface, so that
// the outline moves as a band rather than as a crease).
struct SilhouetteFitOptions {
  int passes = 2;                // each draws the mesh again
  double max_move = 0.0;         // world units per pass (> 0; about a voxel)
  double depth_tolerance = 0.0;  // world units a vertex may lie behind the mesh's depth (> 0)
  int smoothing_passes = 3;      // neighbour rings the moves spread over
  int num_threads = 0;           // 0 or less: every core (the result does not depend on it)
  bool IsValid(std::string* reason) const;
};

struct SilhouetteFitSummary {
  int passes = 0;
  int masked_views = 0;
  int64_t outline_vertices = 0;         // first pass: on some view's outline
  int64_t pulled_vertices = 0;          // first pass: their median move is inwards
  double mean_outside_pixels_first = 0.0;  // outline sightings' mean distance beyond the mask
  double mean_outside_pixels_last = 0.0;   // (0 where on the object), first and last pass
  double mean_move = 0.0;               // world units, over the vertices moved, every pass
  double seconds = 0.0;
  std::string Summary() const;
};

SilhouetteFitSummary FitMeshToSilhouettes(const std::vector<CalibratedView>& views,
                                          const SilhouetteFitOptions& options, TriangleMesh* mesh);

}  // namespace exporter
}  // namespace raycarve
