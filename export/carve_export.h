#pragma once

#include <string>
#include <vector>

#include "carve/carver.h"
#include "export/point_cloud_io.h"

namespace raycarve {
namespace exporter {

// The carved model as a coloured point cloud: one point per surface voxel seen by at least
// `min_views` views (voxels seen by fewer could not be judged and are left out), at the voxel's
// centre, with its colour and an outward normal (towards the empty side: the sum of
// the offsets to the empty or outside voxels among its 26 neighbours, normalised; zero when
// enclosed). World coordinates of the model.
std::vector<ColouredPoint> SurfacePoints(const CarveResult& result, int min_views);

struct MeshSummary {
  size_t num_vertices = 0;
  size_t num_triangles = 0;
};

// The carved volume as a triangle mesh: two triangles per voxel face between a solid voxel and
// an empty or outside one, with the solid voxel's colour on the face's 4 vertices (grey for a
// voxel no view sees). Written through PCL as binary PLY (vertex x y z red green blue; faces),
// under a temporary name and renamed. Throws InputError naming the path on failure.
MeshSummary WriteVoxelMeshPly(const CarveResult& result, const std::string& path);

}  // namespace exporter
}  // namespace raycarve
