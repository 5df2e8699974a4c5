#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace raycarve {

// Why `path` cannot be read as an image file, as a user reads it: "" for a regular file, else
// "not found", "is a folder, not a file", "is a FIFO, socket or device, not a file", or the
// system's reason it cannot be reached (permission denied, a link loop, a name too long).
std::string WhyNotAFile(const std::string& path);

// Checks a JPEG file strictly: libjpeg decodes it whole with its warnings (data that ends early,
// corrupt entropy-coded data) taken as errors. Throws InputError naming the path and libjpeg's
// message; a file that is not a JPEG passes.
void CheckJpegStrictly(const std::string& path);

// The stored size (width x height, before any EXIF orientation, as COLMAP reads it) of an image
// file, from its header where the format allows (JPEG, PNG), else by decoding it. Throws
// InputError naming the path when it cannot be read.
cv::Size ReadImageSize(const std::string& path);

// cv::imread as COLMAP reads a photo (the stored pixels, whatever its EXIF orientation says),
// that never throws OpenCV's exceptions at the caller, and decodes strictly: a file that is not
// a readable regular file, a JPEG that libjpeg would only warn about (cut short, corrupt), or a
// file OpenCV refuses (a header announcing more than its CV_IO_MAX_IMAGE_PIXELS, a corrupt
// stream) throws InputError naming the path and the reason. Returns an empty Mat, as imread
// does, when the file cannot be decoded at all; the caller names what it was for.
cv::Mat ReadImage(const std::string& path, int flags);

}  // namespace raycarve
