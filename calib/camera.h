#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/camera_models.h"
#include "calib/rigid3d.h"
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

// Where the world point `world` falls in a photo of `camera` posed by `cam_from_world`: true, with
// its pixel (COLMAP convention), when it lies in front of the camera and inside the frame.
bool ProjectIntoFrame(const Camera& camera, const Rigid3d& cam_from_world,
                      const Eigen::Vector3d& world, Eigen::Vector2d* pixel);

// The camera of the same photo resampled to new_width x new_height, as COLMAP's
// Camera::Rescale: focal lengths and principal point scale with the image (a single focal length
// by the mean of the two scales); distortion, which acts on normalised coordinates, is unchanged.
// A point's pixel (COLMAP convention, corner at 0) scales by the same factors.
Camera RescaledCamera(const Camera& camera, uint64_t new_width, uint64_t new_height);

// The size a photo of width x height gets under a --max_image_size of `max_size` (COLMAP's
// meaning: the longer side at most max_size, the aspect kept, sides rounded; <= 0: unchanged).
Eigen::Vector2i LimitedImageSize(uint64_t width, uint64_t height, int max_size);

// Throws InputError, prefixed with `context` (file and camera), when the camera cannot be used:
// wrong number of parameters, a non-finite parameter, a non-positive focal length or image size,
// or a focal length below kMinFocalShare of the longer side (a field of view over ~178 degrees).
void ValidateCamera(const Camera& camera, const std::string& context);
constexpr double kMinFocalShare = 0.01;
// The most pixels a camera may have (ValidateCamera): OpenCV's default CV_IO_MAX_IMAGE_PIXELS.
constexpr uint64_t kMaxCameraPixels = uint64_t{1} << 30;

}  // namespace raycarve
