// The OBJ reader (ReadObj: tinyobjloader's parser, then raycarve's own checks of vertices,
// indices and texture coordinates; a material library it names is looked for beside the file),
// then what render and holdout --model do next: draw the mesh.
#include <cstddef>
#include <cstdint>
#include <string>

#include "export/mesh_file_reader.h"
#include "tests/fuzz/mesh_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return raycarve::fuzzing::FuzzMeshFile(
      "obj", ".obj", data, size,
      [](const std::string& path) { return raycarve::exporter::ReadObj(path); });
}
