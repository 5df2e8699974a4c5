#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace raycarve {

// cv::imread as COLMAP reads a photo (the stored pixels, whatever its EXIF orientation says),
// that never throws OpenCV's exceptions at the caller: a file OpenCV refuses (a
// header announcing more than its CV_IO_MAX_IMAGE_PIXELS, a corrupt stream) throws InputError
// naming the path and OpenCV's reason. Returns an empty Mat, as imread does, when the file
// cannot be decoded at all; the caller names what it was for.
cv::Mat ReadImage(const std::string& path, int flags);

}  // namespace raycarve
