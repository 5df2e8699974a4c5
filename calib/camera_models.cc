#include "calib/camera_models.h"

#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Dense>
#include <glog/logging.h>

#include "calib/input_error.h"

namespace raycarve {
namespace {

struct ModelInfo {
  CameraModelId id;
  const char* name;
  const char* params_info;
  int num_params;
};

const ModelInfo kModels[] = {
    {CameraModelId::kSimplePinhole, "SIMPLE_PINHOLE", "f, cx, cy", 3},
    {CameraModelId::kPinhole, "PINHOLE", "fx, fy, cx, cy", 4},
    {CameraModelId::kSimpleRadial, "SIMPLE_RADIAL", "f, cx, cy, k", 4},
    {CameraModelId::kRadial, "RADIAL", "f, cx, cy, k1, k2", 5},
    {CameraModelId::kOpenCv, "OPENCV", "fx, fy, cx, cy, k1, k2, p1, p2", 8},
    {CameraModelId::kOpenCvFisheye, "OPENCV_FISHEYE", "fx, fy, cx, cy, k1, k2, k3, k4", 8},
    {CameraModelId::kFullOpenCv,
     "FULL_OPENCV",
     "fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6",
     12},
    {CameraModelId::kFov, "FOV", "fx, fy, cx, cy, omega", 5},
    {CameraModelId::kSimpleRadialFisheye, "SIMPLE_RADIAL_FISHEYE", "f, cx, cy, k", 4},
    {CameraModelId::kRadialFisheye, "RADIAL_FISHEYE", "f, cx, cy, k1, k2", 5},
    {CameraModelId::kThinPrismFisheye,
     "THIN_PRISM_FISHEYE",
     "fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, sx1, sy1",
     12},
};
constexpr int kNumModels = sizeof(kModels) / sizeof(kModels[0]);

// Models of later COLMAP versions, named so that a refusal can say what the file holds.
const char* const kNewerModels[] = {"RAD_TAN_THIN_PRISM_FISHEYE",
                                    "SIMPLE_DIVISION",
                                    "DIVISION",
                                    "SIMPLE_FISHEYE",
                                    "FISHEYE",
                                    "EUCM",
                                    "EQUIRECTANGULAR"};
constexpr int kFirstNewerModelId = 11;

const ModelInfo& Info(CameraModelId model) {
  const int index = static_cast<int>(model);
  CHECK(index >= 0 && index < kNumModels) << "invalid CameraModelId " << index;
  return kModels[index];
}

// Equidistant fisheye angle scaling: (u, v) * theta_d(theta) / r with theta = atan(r), where
// theta_d = theta * (1 + c[0] theta^2 + c[1] theta^4 + ...).
Eigen::Vector2d FisheyeDistort(const Eigen::Vector2d& uv, const double* coeffs, int num_coeffs) {
  const double r = uv.norm();
  if (r <= std::numeric_limits<double>::epsilon()) {
    return uv;
  }
  const double theta = std::atan(r);
  const double theta2 = theta * theta;
  double power = theta2;
  double factor = 1.0;
  for (int i = 0; i < num_coeffs; ++i) {
    factor += coeffs[i] * power;
    power *= theta2;
  }
  return uv * (theta * factor / r);
}

// Maps undistorted normalised coordinates to distorted normalised coordinates, following the
// distortion functions of COLMAP 3.8's camera models. `extra` are the parameters after the
// focal lengths and principal point.
Eigen::Vector2d Distort(CameraModelId model, const double* extra, const Eigen::Vector2d& uv) {
  const double u = uv.x();
  const double v = uv.y();
  const double r2 = u * u + v * v;
  switch (model) {
    case CameraModelId::kSimplePinhole:
    case CameraModelId::kPinhole:
      return uv;
    case CameraModelId::kSimpleRadial:
      return uv * (1.0 + extra[0] * r2);
    case CameraModelId::kRadial:
      return uv * (1.0 + extra[0] * r2 + extra[1] * r2 * r2);
    case CameraModelId::kOpenCv: {
      const double k1 = extra[0], k2 = extra[1], p1 = extra[2], p2 = extra[3];
      const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
      return {u * radial + 2.0 * p1 * u * v + p2 * (r2 + 2.0 * u * u),
              v * radial + 2.0 * p2 * u * v + p1 * (r2 + 2.0 * v * v)};
    }
    case CameraModelId::kFullOpenCv: {
      const double k1 = extra[0], k2 = extra[1], p1 = extra[2], p2 = extra[3];
      const double k3 = extra[4], k4 = extra[5], k5 = extra[6], k6 = extra[7];
      const double r4 = r2 * r2;
      const double r6 = r4 * r2;
      const double radial =
          (1.0 + k1 * r2 + k2 * r4 + k3 * r6) / (1.0 + k4 * r2 + k5 * r4 + k6 * r6);
      return {u * radial + 2.0 * p1 * u * v + p2 * (r2 + 2.0 * u * u),
              v * radial + 2.0 * p2 * u * v + p1 * (r2 + 2.0 * v * v)};
    }
    case CameraModelId::kOpenCvFisheye:
      return FisheyeDistort(uv, extra, 4);
    case CameraModelId::kSimpleRadialFisheye:
      return FisheyeDistort(uv, extra, 1);
    case CameraModelId::kRadialFisheye:
      return FisheyeDistort(uv, extra, 2);
    case CameraModelId::kFov: {
      // Distorted radius r_d = atan(2 r tan(omega / 2)) / omega; Taylor forms near 0 as COLMAP.
      const double omega = extra[0];
      const double omega2 = omega * omega;
      constexpr double kEpsilon = 1e-4;
      double factor;
      if (omega2 < kEpsilon) {
        factor = omega2 * r2 / 3.0 - omega2 / 12.0 + 1.0;
      } else if (r2 < kEpsilon) {
        const double tan_half = std::tan(omega / 2.0);
        factor = (-2.0 * tan_half * (4.0 * r2 * tan_half * tan_half - 3.0)) / (3.0 * omega);
      } else {
        const double r = std::sqrt(r2);
        factor = std::atan(r * 2.0 * std::tan(omega / 2.0)) / (r * omega);
      }
      return uv * factor;
    }
    case CameraModelId::kThinPrismFisheye: {
      // Equidistant angle first, then radial, tangential and thin-prism terms on the result.
      const Eigen::Vector2d t = FisheyeDistort(uv, nullptr, 0);
      const double k1 = extra[0], k2 = extra[1], p1 = extra[2], p2 = extra[3];
      const double k3 = extra[4], k4 = extra[5], sx1 = extra[6], sy1 = extra[7];
      const double tu = t.x(), tv = t.y();
      const double t2 = tu * tu + tv * tv;
      const double t4 = t2 * t2;
      const double radial = k1 * t2 + k2 * t4 + k3 * t4 * t2 + k4 * t4 * t4;
      return {tu + tu * radial + 2.0 * p1 * tu * tv + p2 * (t2 + 2.0 * tu * tu) + sx1 * t2,
              tv + tv * radial + 2.0 * p2 * tu * tv + p1 * (t2 + 2.0 * tv * tv) + sy1 * t2};
    }
  }
  LOG(FATAL) << "unhandled camera model " << static_cast<int>(model);
  return uv;
}

struct Intrinsics {
  double fx, fy, cx, cy;
  const double* extra;
};

Intrinsics Split(CameraModelId model, const std::vector<double>& params) {
  CHECK_EQ(static_cast<int>(params.size()), CameraModelNumParams(model))
      << "wrong number of parameters for " << CameraModelName(model);
  if (CameraModelHasSingleFocalLength(model)) {
    return {params[0], params[0], params[1], params[2], params.data() + 3};
  }
  return {params[0], params[1], params[2], params[3], params.data() + 4};
}

}  // namespace

const std::vector<CameraModelId>& SupportedCameraModels() {
  static const std::vector<CameraModelId> models = [] {
    std::vector<CameraModelId> all;
    for (const ModelInfo& info : kModels) all.push_back(info.id);
    return all;
  }();
  return models;
}

std::string CameraModelName(CameraModelId model) { return Info(model).name; }
std::string CameraModelParamsInfo(CameraModelId model) { return Info(model).params_info; }
int CameraModelNumParams(CameraModelId model) { return Info(model).num_params; }

bool CameraModelHasDistortion(CameraModelId model) {
  return model != CameraModelId::kSimplePinhole && model != CameraModelId::kPinhole;
}

bool CameraModelHasSingleFocalLength(CameraModelId model) {
  return model == CameraModelId::kSimplePinhole || model == CameraModelId::kSimpleRadial ||
         model == CameraModelId::kRadial || model == CameraModelId::kSimpleRadialFisheye ||
         model == CameraModelId::kRadialFisheye;
}

CameraModelId CameraModelIdFromInt(int model_id, const std::string& context) {
  if (model_id >= 0 && model_id < kNumModels) {
    return static_cast<CameraModelId>(model_id);
  }
  std::ostringstream message;
  message << context << ": camera model id " << model_id;
  // In 64 bits: ids near INT_MIN must not overflow (found by fuzzing).
  const int64_t newer = static_cast<int64_t>(model_id) - kFirstNewerModelId;
  if (newer >= 0 && newer < static_cast<int64_t>(sizeof(kNewerModels) / sizeof(kNewerModels[0]))) {
    message << " (" << kNewerModels[newer] << ", from a COLMAP newer than 3.8)";
  }
  message << " is not supported; raycarve reads COLMAP 3.8's models 0-10 "
             "(SIMPLE_PINHOLE ... THIN_PRISM_FISHEYE)";
  throw InputError(message.str());
}

CameraModelId CameraModelIdFromName(const std::string& name, const std::string& context) {
  for (const ModelInfo& info : kModels) {
    if (name == info.name) return info.id;
  }
  std::ostringstream message;
  message << context << ": camera model '" << name << "'";
  for (const char* newer : kNewerModels) {
    if (name == newer) message << " (from a COLMAP newer than 3.8)";
  }
  message << " is not supported; raycarve reads COLMAP 3.8's models 0-10 "
             "(SIMPLE_PINHOLE ... THIN_PRISM_FISHEYE)";
  throw InputError(message.str());
}

Eigen::Vector2d ImgFromCam(CameraModelId model,
                           const std::vector<double>& params,
                           const Eigen::Vector2d& normalized) {
  const Intrinsics k = Split(model, params);
  const Eigen::Vector2d d = Distort(model, k.extra, normalized);
  return {k.fx * d.x() + k.cx, k.fy * d.y() + k.cy};
}

Eigen::Vector2d CamFromImg(CameraModelId model,
                           const std::vector<double>& params,
                           const Eigen::Vector2d& pixel) {
  const Intrinsics k = Split(model, params);
  const Eigen::Vector2d target((pixel.x() - k.cx) / k.fx, (pixel.y() - k.cy) / k.fy);
  if (!CameraModelHasDistortion(model)) {
    return target;
  }
  // Damped Newton on Distort(uv) = target with a central-difference Jacobian.
  constexpr int kMaxIterations = 100;
  constexpr double kTolerance = 1e-12;
  Eigen::Vector2d uv = target;
  Eigen::Vector2d residual = Distort(model, k.extra, uv) - target;
  for (int iteration = 0; iteration < kMaxIterations && residual.norm() > kTolerance;
       ++iteration) {
    Eigen::Matrix2d jacobian;
    for (int axis = 0; axis < 2; ++axis) {
      const double h = 1e-7 * std::max(1.0, std::abs(uv[axis]));
      Eigen::Vector2d plus = uv, minus = uv;
      plus[axis] += h;
      minus[axis] -= h;
      jacobian.col(axis) =
          (Distort(model, k.extra, plus) - Distort(model, k.extra, minus)) / (2.0 * h);
    }
    const Eigen::Vector2d step = jacobian.fullPivLu().solve(residual);
    if (!step.allFinite()) break;
    double scale = 1.0;
    Eigen::Vector2d candidate = uv - step;
    Eigen::Vector2d candidate_residual = Distort(model, k.extra, candidate) - target;
    while (candidate_residual.norm() >= residual.norm() && scale > 1e-6) {
      scale *= 0.5;
      candidate = uv - scale * step;
      candidate_residual = Distort(model, k.extra, candidate) - target;
    }
    if (candidate_residual.norm() >= residual.norm()) break;
    uv = candidate;
    residual = candidate_residual;
  }
  if (!(residual.norm() <= 1e-9)) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan};
  }
  return uv;
}

}  // namespace raycarve
