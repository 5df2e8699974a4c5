#pragma once
// What the mesh readers' fuzz targets do with a mesh read: draw it as render and holdout --model
// do, into a small camera at the origin looking down +z (its texture sampled where it has one).

#include "export/mesh_renderer.h"

namespace raycarve {
namespace fuzzing {

inline void DrawMesh(const exporter::TriangleMesh& mesh) {
  CalibratedView view;
  view.width = 32;
  view.height = 24;
  view.K << 30, 0, 16, 0, 30, 12, 0, 0, 1;
  view.P = view.K * view.cam_from_world.ToMatrix();
  exporter::RenderMesh(mesh, view);
}

}  // namespace fuzzing
}  // namespace raycarve
