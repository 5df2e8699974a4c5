#pragma once

#include <cstdint>
#include <vector>

#include "calib/calibrated_view.h"
#include "export/point_renderer.h"
#include "export/surface_mesh.h"

namespace raycarve {
namespace exporter {

// Draws a triangle mesh into one view's pinhole camera (K, cam_from_world, size; its pixels are
// not used) with a depth buffer: a pixel is covered when its centre (COLMAP convention) lies in
// a triangle's projection, takes the depth of the nearest such triangle along the optical axis,
// and the perspective-correct blend of its vertices' colours (grey 128 where the mesh has none),
// or, for a textured mesh, the texture bilinearly sampled at the blend of its corners' coordinates.
// Triangles with a vertex at or behind the camera plane are skipped. Both sides are drawn, so a
// mesh's inside never shows through a hole, unless `front_faces_only`: then triangles whose
// winding (counter-clockwise seen from outside, as MeshSolidVoxels makes them) faces away from
// the camera are skipped. For a closed mesh and a camera outside it that gives the same depth
// buffer in about half the time: the first surface a ray meets is one it enters, which faces
// the camera. Cost: the triangles' projected area.
Rendering RenderMesh(const TriangleMesh& mesh, const CalibratedView& view,
                     bool front_faces_only = false);
// RenderMesh's depth buffer alone (the same values), without the colour and silhouette images:
// what finding the vertices a view sees needs, for less memory traffic.
cv::Mat RenderMeshDepth(const TriangleMesh& mesh, const CalibratedView& view,
                        bool front_faces_only = false);

// Which of a mesh's parts cover each pixel of `view`, front faces only (closed parts seen from
// outside): `count` (CV_8UC1, saturating at 255) gets how many parts cover the pixel, `last_part`
// (CV_32SC1, -1 where none) the last of them, and `covered` per part the pixels it covers.
// `triangle_part` gives each triangle's part (0 to num_parts - 1), in ascending order: the
// triangles must be grouped by part.
void DrawMeshParts(const TriangleMesh& mesh, const std::vector<int>& triangle_part, int num_parts,
                   const CalibratedView& view, cv::Mat* count, cv::Mat* last_part,
                   std::vector<int64_t>* covered);

}  // namespace exporter
}  // namespace raycarve
