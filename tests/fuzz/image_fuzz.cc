// Photo and mask decoding as the views are read: ReadImage (strict JPEG check, then OpenCV) in
// colour and in grey, on any bytes written to a file.
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

#include "calib/image_reader.h"
#include "calib/input_error.h"
#include "tests/fuzz/fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // OpenCV sizes its buffers from a header: no input may announce more than a small photo.
  static const bool limited = [] {
    setenv("OPENCV_IO_MAX_IMAGE_PIXELS", "4000000", 1);
    return true;
  }();
  (void)limited;
  const std::string path = raycarve::fuzzing::WriteInputFile("image", ".img", data, size);
  for (const int flags : {cv::IMREAD_COLOR, cv::IMREAD_GRAYSCALE}) {
    try {
      const cv::Mat image = raycarve::ReadImage(path, flags);
      if (!image.empty() && image.total() == 0) __builtin_trap();
    } catch (const raycarve::InputError&) {
    }
  }
  return 0;
}
