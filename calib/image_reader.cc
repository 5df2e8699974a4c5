#include "calib/image_reader.h"

#include <opencv2/imgcodecs.hpp>

#include "calib/input_error.h"

namespace raycarve {

cv::Mat ReadImage(const std::string& path, int flags) {
  try {
    return cv::imread(path, flags);
  } catch (const cv::Exception& error) {
    throw InputError(path + ": OpenCV refuses to decode it (" + error.err + ")");
  }
}

}  // namespace raycarve
