// The glTF reader (ReadGltf: tinygltf's parser, then raycarve's own checks of accessors, indices
// and node trees, and the texture atlas), then what render and holdout --model do next: draw the
// mesh with its texture.
#include <cstddef>
#include <cstdint>
#include <string>

#include "export/mesh_file_reader.h"
#include "tests/fuzz/mesh_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return raycarve::fuzzing::FuzzMeshFile(
      "gltf", ".glb", data, size,
      [](const std::string& path) { return raycarve::exporter::ReadGltf(path); });
}
