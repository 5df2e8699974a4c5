// The Middlebury calibration reader (import_middlebury), every photo 640x480.
#include <sstream>
#include <string>

#include "calib/input_error.h"
#include "calib/middlebury.h"
#include "tests/fuzz/fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::istringstream stream(std::string(reinterpret_cast<const char*>(data), size));
  try {
    raycarve::ReadMiddleburyParameters(
        stream, "x_par.txt", [](const std::string&) { return Eigen::Vector2i(640, 480); },
        raycarve::MiddleburyImportOptions());
  } catch (const raycarve::InputError&) {
  }
  return 0;
}
