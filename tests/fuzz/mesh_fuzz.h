#pragma once
// What the mesh readers' fuzz targets do with a mesh read: draw it as render and holdout --model
// do, into a small camera at the origin looking down +z (its texture sampled where it has one).

#include <cstddef>
#include <cstdint>
#include <string>

#include "calib/input_error.h"
#include "export/mesh_renderer.h"
#include "tests/fuzz/fuzz_target.h"

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

// One fuzz input as a mesh file: written as a file named for `name` with `extension`, read by
// `read` (refusals with InputError are answers), drawn.
template <typename Read>
int FuzzMeshFile(const char* name, const char* extension, const uint8_t* data, size_t size,
                 Read read) {
  const std::string path = WriteInputFile(name, extension, data, size);
  try {
    DrawMesh(read(path));
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace fuzzing
}  // namespace raycarve
