#pragma once
// What the smooth mesh leaves out because the photos never saw it as a surface: the volume box's
// walls, the held ground's fill, what lies beyond the photos' frames and, on a scene, what they
// see from fewer than two directions. Per-vertex marks; MeshCarvedModel removes the triangles.

#include <cstdint>
#include <vector>

#include "calib/calibrated_view.h"
#include "carve/ground.h"
#include "carve/voxel_grid.h"
#include "export/surface_mesh.h"

namespace raycarve {
namespace exporter {

// Per vertex of `mesh`, 1 where fewer than `min_views` of `views` hold it in their frames (in
// front of the camera, on a pixel of the photo), occlusion aside. The carve never judged what lies
// there (a voxel that fewer than min_views views see is kept), so a surface there is the edge of
// what the photos cover, as the box's walls are where the box cuts the scene: not a surface the
// photos saw. Inside the box of a capture from one side (a scene), the space near the cameras and
// beside their frames is such; an object's box is held by every photo of a ring.
std::vector<uint8_t> UncoveredVertices(const TriangleMesh& mesh,
                                       const std::vector<CalibratedView>& views, int min_views);
// Per vertex of `mesh`, 1 where fewer than `min_views` of `views` see it: in the frame and no
// more than `tolerance` behind the nearest surface of the mesh there (RenderMeshDepth, both
// faces). UncoveredVertices with the mesh's own occlusion: what fewer see, the carve never judged.
std::vector<uint8_t> UnseenVertices(const TriangleMesh& mesh, const std::vector<CalibratedView>& views,
                                    int min_views, double tolerance);
// Clears the marks of `unseen` (UnseenVertices) on the vertices of `mesh` that lie within `reach`
// along its edges of a vertex neither unseen nor `excluded` (the walls, the ground's fill, beyond
// the frames): where two photos' view of a surface ends, within a voxel, is below what the carve
// resolves, and leaving it out opens the subject's rim to a photo a little past the training ones
// (a hole into the ball's inside, drawn black). Returns how many it cleared.
int64_t KeepUnseenNearSeen(const TriangleMesh& mesh, const std::vector<uint8_t>& excluded,
                           double reach, std::vector<uint8_t>* unseen);
// Per vertex of `mesh` (with normals), 1 where it lies on the wall of `grid` (see
// ModelMesh::on_grid_wall).
std::vector<uint8_t> GridWallVertices(const TriangleMesh& mesh, const VoxelGrid& grid);
// Per vertex of `mesh` (with normals), 1 where it lies on the held ground's fill: its foot on the
// plane within 1.5 voxels of the ground, and more than the ground's depth and a voxel below the
// plane, or more than its depth and a quarter voxel below it facing sideways or down (the
// normal over 60 degrees from the plane's). The top of the ground, facing up, is kept.
std::vector<uint8_t> GroundFillVertices(const TriangleMesh& mesh, const Ground& ground,
                                        double voxel_size);

}  // namespace exporter
}  // namespace raycarve
