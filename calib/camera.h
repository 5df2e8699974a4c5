#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/camera_models.h"
#include "calib/types.h"

namespace raycarve {

// One COLMAP camera: a model, its parameters and the image size in pixels.
struct Camera {
  camera_t camera_id = 0;
  CameraModelId model = CameraModelId::kPinhole;
  uint64_t width = 0;
  uint64_t height = 0;
  std::vector<double> params;

  // Normalised camera coordinates (x/z, y/z) <-> pixel (COLMAP convention). See camera_models.h.
  Eigen::Vector2d ImgFromCam(const Eigen::Vector2d& normalized) const;
  Eigen::Vector2d CamFromImg(const Eigen::Vector2d& pixel) const;

  double FocalLengthX() const;
  double FocalLengthY() const;
  Eigen::Vector2d PrincipalPoint() const;
};

// Throws InputError, prefixed with `context` (file and camera), when the camera cannot be used:
// wrong number of parameters, a non-finite parameter, a non-positive focal length or image size.
void ValidateCamera(const Camera& camera, const std::string& context);
// The most pixels a camera may have (ValidateCamera): OpenCV's default CV_IO_MAX_IMAGE_PIXELS.
constexpr uint64_t kMaxCameraPixels = uint64_t{1} << 30;

}  // namespace raycarve
