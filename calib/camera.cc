#include "calib/camera.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "calib/input_error.h"

namespace raycarve {
Eigen::Vector2d Camera::ImgFromCam(const Eigen::Vector2d& normalized) const {
  return raycarve::ImgFromCam(model, params, normalized);
}

bool ProjectIntoFrame(const Camera& camera, const Rigid3d& cam_from_world,
                      const Eigen::Vector3d& world, Eigen::Vector2d* pixel) {
  const Eigen::Vector3d local = cam_from_world * world;
  if (!(local.z() > 1e-9)) return false;
  *pixel = camera.ImgFromCam(local.head<2>() / local.z());
  return pixel->allFinite() && pixel->x() >= 0.0 && pixel->y() >= 0.0 &&
         pixel->x() < static_cast<double>(camera.width) &&
         pixel->y() < static_cast<double>(camera.height);
}

Eigen::Vector2d Camera::CamFromImg(const Eigen::Vector2d& pixel) const {
  return raycarve::CamFromImg(model, params, pixel);
}

double Camera::FocalLengthX() const { return params.at(0); }

double Camera::FocalLengthY() const {
  return CameraModelHasSingleFocalLength(model) ? params.at(0) : params.at(1);
}

Eigen::Vector2d Camera::PrincipalPoint() const {
  return CameraModelHasSingleFocalLength(model) ? Eigen::Vector2d(params.at(1), params.at(2))
                                                : Eigen::Vector2d(params.at(2), params.at(3));
}

Camera RescaledCamera(const Camera& camera, uint64_t new_width, uint64_t new_height) {
  Camera rescaled = camera;
  const double scale_x = static_cast<double>(new_width) / camera.width;
  const double scale_y = static_cast<double>(new_height) / camera.height;
  rescaled.width = new_width;
  rescaled.height = new_height;
  if (CameraModelHasSingleFocalLength(camera.model)) {
    rescaled.params.at(0) *= 0.5 * (scale_x + scale_y);
    rescaled.params.at(1) *= scale_x;
    rescaled.params.at(2) *= scale_y;
  } else {
    rescaled.params.at(0) *= scale_x;
    rescaled.params.at(1) *= scale_y;
    rescaled.params.at(2) *= scale_x;
    rescaled.params.at(3) *= scale_y;
  }
  return rescaled;
}

Eigen::Vector2i LimitedImageSize(uint64_t width, uint64_t height, int max_size) {
  const uint64_t longer = std::max(width, height);
  if (max_size <= 0 || longer <= static_cast<uint64_t>(max_size)) {
    return Eigen::Vector2i(static_cast<int>(width), static_cast<int>(height));
  }
  const double scale = static_cast<double>(max_size) / longer;
  return Eigen::Vector2i(std::max(1, static_cast<int>(std::lround(width * scale))),
                         std::max(1, static_cast<int>(std::lround(height * scale))));
}

void ValidateCamera(const Camera& camera, const std::string& context) {
  const int expected = CameraModelNumParams(camera.model);
  std::ostringstream prefix;
  prefix << context << ": camera " << camera.camera_id << " (" << CameraModelName(camera.model)
         << ")";
  if (static_cast<int>(camera.params.size()) != expected) {
    throw InputError(prefix.str() + ": params: expected " + std::to_string(expected) + " (" +
                     CameraModelParamsInfo(camera.model) + "), found " +
                     std::to_string(camera.params.size()));
  }
  for (size_t i = 0; i < camera.params.size(); ++i) {
    if (!std::isfinite(camera.params[i])) {
      throw InputError(prefix.str() + ": params[" + std::to_string(i) + "] is not finite");
    }
  }
  if (camera.width == 0 || camera.height == 0) {
    throw InputError(prefix.str() + ": width/height must be positive, found " +
                     std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
  // OpenCV decodes no photo of more than 2^30 pixels (CV_IO_MAX_IMAGE_PIXELS); a camera larger
  // than any photo it could have taken is a broken file, refused before anything is allocated.
  if (static_cast<uint64_t>(camera.width) * camera.height > kMaxCameraPixels) {
    throw InputError(prefix.str() + ": width/height " + std::to_string(camera.width) + "x" +
                     std::to_string(camera.height) + " is more than " +
                     std::to_string(kMaxCameraPixels) + " pixels, larger than any photo can be read");
  }
  if (!(camera.FocalLengthX() > 0.0) || !(camera.FocalLengthY() > 0.0)) {
    throw InputError(prefix.str() + ": focal length must be positive");
  }
  // A focal length below a hundredth of the photo's longer side is a field of view of more than
  // about 178 degrees across it: wider than any lens, fisheyes included (an equidistant fisheye
  // seeing 180 degrees has f = side / pi). Such a value is a broken or mistyped calibration.
  const double longer = static_cast<double>(std::max(camera.width, camera.height));
  const double focal = std::min(camera.FocalLengthX(), camera.FocalLengthY());
  if (focal < kMinFocalShare * longer) {
    std::ostringstream text;
    text << prefix.str() << ": focal length " << focal << " px is less than "
         << kMinFocalShare * 100 << "% of the photo's longer side (" << longer
         << " px): a field of view wider than any lens; check the camera's parameters";
    throw InputError(text.str());
  }
}

}  // namespace raycarve
