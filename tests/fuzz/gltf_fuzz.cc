// The glTF reader (ReadGltf: tinygltf's parser, then raycarve's own checks of accessors, indices
// and node trees, and the texture atlas), then what render and holdout --model do next: draw the
// mesh with its texture.
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "calib/input_error.h"
#include "export/mesh_file_reader.h"
#include "export/mesh_renderer.h"
#include "tests/fuzz/fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = raycarve::fuzzing::WriteInputFile("gltf", ".glb", data, size);
  try {
    const raycarve::exporter::TriangleMesh mesh = raycarve::exporter::ReadGltf(path);
    raycarve::CalibratedView view;
    view.width = 32;
    view.height = 24;
    view.K << 30, 0, 16, 0, 30, 12, 0, 0, 1;
    view.P = view.K * view.cam_from_world.ToMatrix();
    raycarve::exporter::RenderMesh(mesh, view);
  } catch (const raycarve::InputError&) {
  }
  return 0;
}
