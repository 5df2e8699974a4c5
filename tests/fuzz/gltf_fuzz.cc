// The glTF reader (ReadGltf: tinygltf's parser, then raycarve's own checks of accessors, indices
// and node trees, and the texture atlas), then what render and holdout --model do next: draw the
// mesh with its texture.
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "calib/input_error.h"
#include "export/mesh_file_reader.h"
#include "tests/fuzz/fuzz_target.h"
#include "tests/fuzz/mesh_fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = raycarve::fuzzing::WriteInputFile("gltf", ".glb", data, size);
  try {
    raycarve::fuzzing::DrawMesh(raycarve::exporter::ReadGltf(path));
  } catch (const raycarve::InputError&) {
  }
  return 0;
}
