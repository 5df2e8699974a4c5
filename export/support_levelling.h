#pragma once
// Levelling the mesh onto the plane the subject stands on (a table, a floor, a mat): the carve
// leaves such a surface a voxel thick and the photos, which see it at a slant, cannot place it
// within that voxel; the sparse points on it can.

#include <cstdint>
#include <string>

#include "carve/ground.h"
#include "export/surface_mesh.h"

namespace raycarve {
namespace exporter {

struct SupportLevelling {
  int64_t vertices = 0;      // vertices moved onto (or towards) the plane
  double mean_move = 0.0;    // world units, over those vertices
  double band = 0.0;         // world units: how far from the plane a vertex could be levelled
                             // (two voxels, or the band asked for where wider)
  int64_t undone = 0;        // of them, moved back where levelling made the mesh fold
  std::string Summary() const;
};

// A vertex faces down when its normal is within this many degrees of the plane's opposite: the
// underside of a thin top (a mat), which goes under the plane rather than onto it.
constexpr double kLevelledNormalDegrees = 60.0;

// The band is two voxels, or `min_band` (world units) where that is wider. Moves each vertex of
// `mesh` that lies within half the band of the plane of `support`, above or below, onto the plane,
// but one that faces down (kLevelledNormalDegrees) to half a voxel below it where it is higher;
// one within the band part of the way (all of it at half the band, none at the band, so that the
// surface joins what stays); only where the sparse points show the plane: the vertex's foot on
// the plane is on `support`'s footprint (GroundMap::At). Recomputes the normals. An empty
// `support` moves nothing. The pipeline passes two voxels of the default grid over the same box
// as `min_band`: a finer grid levels what the default grid does (over a plain floor the photo
// hull bulges a few fine voxels high, which colour cannot tell from the floor and the sparse
// points place on it).
SupportLevelling LevelOntoSupport(const Ground& support, double voxel_size, double min_band,
                                  TriangleMesh* mesh);

}  // namespace exporter
}  // namespace raycarve
