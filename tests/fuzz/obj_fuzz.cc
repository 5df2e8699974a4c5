// The OBJ reader (ReadObj: tinyobjloader's parser, then raycarve's own checks of vertices,
// indices and texture coordinates; a material library it names is looked for beside the file),
// then what render and holdout --model do next: draw the mesh.
#include <string>

#include "calib/input_error.h"
#include "export/mesh_file_reader.h"
#include "tests/fuzz/fuzz_target.h"
#include "tests/fuzz/mesh_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = raycarve::fuzzing::WriteInputFile("obj", ".obj", data, size);
  try {
    raycarve::fuzzing::DrawMesh(raycarve::exporter::ReadObj(path));
  } catch (const raycarve::InputError&) {
  }
  return 0;
}
