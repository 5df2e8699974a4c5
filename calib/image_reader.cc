#include "calib/image_reader.h"

#include <opencv2/imgcodecs.hpp>

#include "calib/input_error.h"

namespace raycarve {

cv::Mat ReadImage(const std::string& path, int flags) {
  // COLMAP reads the pixels as stored and registers them so; OpenCV would turn a photo by its
  // EXIF orientation (a phone held upright: 3000x4000 against COLMAP's 4000x3000, or upside
  // down: the same size, silently turned). IMREAD_UNCHANGED ignores the orientation already.
  if (flags != cv::IMREAD_UNCHANGED) flags |= cv::IMREAD_IGNORE_ORIENTATION;
  try {
    return cv::imread(path, flags);
  } catch (const cv::Exception& error) {
    throw InputError(path + ": OpenCV refuses to decode it (" + error.err + ")");
  }
}

}  // namespace raycarve
