// The COLMAP model readers, then what model_info does next with what was read: the
// cross-file checks and the bounds. The first byte picks the reader; the rest is the file.
#include <sstream>
#include <string>

#include "calib/bounds.h"
#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "tests/fuzz/fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  std::istringstream stream(std::string(reinterpret_cast<const char*>(data) + 1, size - 1));
  raycarve::Reconstruction reconstruction;
  try {
    switch (data[0] % 6) {
      case 0: raycarve::ReadCamerasBinary(stream, "cameras.bin", &reconstruction); break;
      case 1: raycarve::ReadImagesBinary(stream, "images.bin", &reconstruction); break;
      case 2: raycarve::ReadPoints3DBinary(stream, "points3D.bin", &reconstruction); break;
      case 3: raycarve::ReadCamerasText(stream, "cameras.txt", &reconstruction); break;
      case 4: raycarve::ReadImagesText(stream, "images.txt", &reconstruction); break;
      default: raycarve::ReadPoints3DText(stream, "points3D.txt", &reconstruction); break;
    }
    raycarve::ValidateReconstruction(reconstruction, "model");
    raycarve::ComputeBounds(reconstruction, raycarve::BoundsOptions(), "model");
  } catch (const raycarve::InputError&) {
    // Bad input, named: what a command prints before exit 1.
  }
  return 0;
}
