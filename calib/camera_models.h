#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace raycarve {

// The camera models of COLMAP 3.8 (model ids 0-10), with COLMAP's ids, names and parameter
// orders. Later COLMAP versions add ids 11-17; they are refused with a message naming them.
enum class CameraModelId : int {
  kSimplePinhole = 0,        // f, cx, cy
  kPinhole = 1,              // fx, fy, cx, cy
  kSimpleRadial = 2,         // f, cx, cy, k
  kRadial = 3,               // f, cx, cy, k1, k2
  kOpenCv = 4,               // fx, fy, cx, cy, k1, k2, p1, p2
  kOpenCvFisheye = 5,        // fx, fy, cx, cy, k1, k2, k3, k4
  kFullOpenCv = 6,           // fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6
  kFov = 7,                  // fx, fy, cx, cy, omega
  kSimpleRadialFisheye = 8,  // f, cx, cy, k
  kRadialFisheye = 9,        // f, cx, cy, k1, k2
  kThinPrismFisheye = 10,    // fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, sx1, sy1
};

// All supported models, in id order.
const std::vector<CameraModelId>& SupportedCameraModels();

// COLMAP's name ("OPENCV_FISHEYE") and the comma-separated parameter list ("fx, fy, cx, cy, ...").
std::string CameraModelName(CameraModelId model);
std::string CameraModelParamsInfo(CameraModelId model);
int CameraModelNumParams(CameraModelId model);
// False for SIMPLE_PINHOLE and PINHOLE, whose images need no undistortion.
bool CameraModelHasDistortion(CameraModelId model);
// True for models with one focal length f (parameters f, cx, cy, ...), false for fx, fy.
bool CameraModelHasSingleFocalLength(CameraModelId model);

// Conversions from file values. On an unknown or unsupported value they throw InputError whose
// message starts with `context` (e.g. "cameras.bin: camera 3: model_id") and names the model
// where COLMAP knows it ("model 12 (SIMPLE_DIVISION) is not supported ...").
CameraModelId CameraModelIdFromInt(int model_id, const std::string& context);
CameraModelId CameraModelIdFromName(const std::string& name, const std::string& context);

// Projection of a point given in normalised camera coordinates (x/z, y/z) to a pixel, in
// COLMAP's pixel convention (centre of the top-left pixel at (0.5, 0.5)). `params` must hold
// CameraModelNumParams(model) values (CHECKed).
Eigen::Vector2d ImgFromCam(CameraModelId model,
                           const std::vector<double>& params,
                           const Eigen::Vector2d& normalized);

// Inverse of ImgFromCam: the normalised camera coordinates whose projection is `pixel`.
// Distortion is inverted by damped Newton iterations to better than 1e-12 in normalised
// coordinates; a pixel outside the model's valid domain (e.g. beyond a fisheye's 90 degrees)
// returns NaN coordinates.
Eigen::Vector2d CamFromImg(CameraModelId model,
                           const std::vector<double>& params,
                           const Eigen::Vector2d& pixel);

}  // namespace raycarve
