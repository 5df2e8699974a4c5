#pragma once

#include <opencv2/core.hpp>

#include "calib/camera.h"

namespace raycarve {

// The pinhole camera that raycarve resamples a distorted image into: same image size, focal
// lengths and principal point as `camera` (for SIMPLE_* models fx = fy = f), model PINHOLE.
// Pinhole cameras map to themselves.
Camera PinholeCameraFor(const Camera& camera);

// Look-up tables for cv::remap: for each pixel (row, col) of PinholeCameraFor(camera), the
// OpenCV coordinates in the distorted image of the same viewing ray (CV_32FC1 each). Built by
// projecting every pinhole pixel centre's ray through `camera`'s model, so every COLMAP 3.8 model
// is handled the same way. Cost: one ImgFromCam per pixel.
struct UndistortionMaps {
  Camera pinhole;
  cv::Mat map_x;
  cv::Mat map_y;
};
UndistortionMaps BuildUndistortionMaps(const Camera& camera);

// Resamples `distorted` (any type cv::remap accepts; size camera.width x camera.height, CHECKed)
// into the pinhole camera, bilinearly. `valid` (CV_8UC1) is 255 where the source pixel lies in
// the distorted image and 0 where the pinhole view sees beyond it (those pixels are set to 0).
// For a pinhole camera the image is returned unchanged and `valid` is all 255.
void UndistortImage(const UndistortionMaps& maps,
                    const cv::Mat& distorted,
                    cv::Mat* undistorted,
                    cv::Mat* valid);

}  // namespace raycarve
