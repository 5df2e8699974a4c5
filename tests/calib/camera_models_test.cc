#include "calib/camera_models.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "calib/camera.h"
#include "calib/input_error.h"
#include "samples/synthetic_scene.h"
#include "calib/pixel.h"

namespace raycarve {
namespace {

// Parameters with clearly visible distortion for a 640x480 camera of focal length 500.
std::vector<double> DistortedParams(CameraModelId model) {
  switch (model) {
    case CameraModelId::kSimplePinhole: return {500, 321, 239};
    case CameraModelId::kPinhole: return {500, 510, 321, 239};
    case CameraModelId::kSimpleRadial: return {500, 321, 239, -0.15};
    case CameraModelId::kRadial: return {500, 321, 239, -0.2, 0.05};
    case CameraModelId::kOpenCv: return {500, 510, 321, 239, -0.2, 0.05, 0.003, -0.002};
    case CameraModelId::kOpenCvFisheye: return {500, 510, 321, 239, 0.1, -0.05, 0.02, -0.005};
    case CameraModelId::kFullOpenCv:
      return {500, 510, 321, 239, -0.2, 0.05, 0.003, -0.002, 0.01, 0.1, 0.02, 0.003};
    case CameraModelId::kFov: return {500, 510, 321, 239, 0.9};
    case CameraModelId::kSimpleRadialFisheye: return {500, 321, 239, 0.1};
    case CameraModelId::kRadialFisheye: return {500, 321, 239, 0.1, -0.03};
    case CameraModelId::kThinPrismFisheye:
      return {500, 510, 321, 239, 0.05, -0.02, 0.002, -0.003, 0.004, -0.002, 0.003, -0.002};
  }
  return {};
}

TEST(CameraModels, CoverCOLMAP38IdsZeroToTenWithTheirParameterCounts) {
  const std::vector<CameraModelId>& models = SupportedCameraModels();
  ASSERT_EQ(models.size(), 11u);
  const int expected_counts[] = {3, 4, 4, 5, 8, 8, 12, 5, 4, 5, 12};
  for (int id = 0; id <= 10; ++id) {
    EXPECT_EQ(static_cast<int>(models[id]), id);
    EXPECT_EQ(CameraModelNumParams(models[id]), expected_counts[id]) << CameraModelName(models[id]);
    EXPECT_EQ(CameraModelIdFromName(CameraModelName(models[id]), "test"), models[id]);
    EXPECT_EQ(CameraModelIdFromInt(id, "test"), models[id]);
  }
}

TEST(CameraModels, ProjectionAndUnprojectionRoundTripOnAPixelGridForEveryModel) {
  for (CameraModelId model : SupportedCameraModels()) {
    const std::vector<double> params = DistortedParams(model);
    double worst_pixel = 0.0;
    for (double y = 0.5; y < 480; y += 16.0) {
      for (double x = 0.5; x < 640; x += 16.0) {
        const Eigen::Vector2d pixel(x, y);
        const Eigen::Vector2d normalized = CamFromImg(model, params, pixel);
        ASSERT_TRUE(normalized.allFinite()) << CameraModelName(model) << " at " << x << "," << y;
        worst_pixel = std::max(worst_pixel, (ImgFromCam(model, params, normalized) - pixel).norm());
      }
    }
    EXPECT_LT(worst_pixel, 1e-6) << CameraModelName(model);
  }
}

TEST(CameraModels, UnprojectionInvertsProjectionInNormalisedCoordinates) {
  for (CameraModelId model : SupportedCameraModels()) {
    const std::vector<double> params = DistortedParams(model);
    for (double v = -0.45; v <= 0.45; v += 0.05) {
      for (double u = -0.6; u <= 0.6; u += 0.05) {
        const Eigen::Vector2d normalized(u, v);
        const Eigen::Vector2d back = CamFromImg(model, params, ImgFromCam(model, params, normalized));
        EXPECT_LT((back - normalized).norm(), 1e-9) << CameraModelName(model) << " " << u << "," << v;
      }
    }
  }
}

// Values worked out by hand (and in a calculator) from the models' formulas.
TEST(CameraModels, ProjectKnownPointsToHandCheckedPixels) {
  const Eigen::Vector2d p(0.3, 0.4);  // r^2 = 0.25, r = 0.5
  auto project = [](CameraModelId model, std::vector<double> params, Eigen::Vector2d uv) {
    return ImgFromCam(model, params, uv);
  };
  EXPECT_TRUE(project(CameraModelId::kSimplePinhole, {100, 50, 40}, {0.1, -0.2})
                  .isApprox(Eigen::Vector2d(60, 20), 1e-12));
  // 1 + k r^2 = 1.025.
  EXPECT_TRUE(project(CameraModelId::kSimpleRadial, {100, 50, 40, 0.1}, p)
                  .isApprox(Eigen::Vector2d(80.75, 81.0), 1e-12));
  // 1 + 0.1 * 0.25 + 0.01 * 0.0625 = 1.025625.
  EXPECT_TRUE(project(CameraModelId::kRadial, {100, 50, 40, 0.1, 0.01}, p)
                  .isApprox(Eigen::Vector2d(80.76875, 81.025), 1e-12));
  // u' = 0.3 * 1.025 + 2 * 0.01 * 0.12 + 0.02 * (0.25 + 0.18) = 0.3185,
  // v' = 0.4 * 1.025 + 2 * 0.02 * 0.12 + 0.01 * (0.25 + 0.32) = 0.4205.
  EXPECT_TRUE(project(CameraModelId::kOpenCv, {100, 200, 50, 40, 0.1, 0, 0.01, 0.02}, p)
                  .isApprox(Eigen::Vector2d(81.85, 124.1), 1e-12));
  // Equidistant fisheye without coefficients: r_d = atan(1) = pi / 4.
  EXPECT_NEAR(project(CameraModelId::kOpenCvFisheye, {100, 100, 50, 40, 0, 0, 0, 0}, {1.0, 0.0}).x(),
              50 + 100 * M_PI / 4, 1e-12);
  // Rational radial term 1 / (1 + k4 r^2) = 1 / 1.025.
  EXPECT_TRUE(
      project(CameraModelId::kFullOpenCv, {100, 200, 50, 40, 0, 0, 0, 0, 0, 0.1, 0, 0}, p)
          .isApprox(Eigen::Vector2d(79.26829268292683, 118.04878048780489), 1e-12));
  // FOV with omega = pi/2: r_d = atan(2 r tan(pi/4)) / (pi/2) = atan(1) / (pi/2) = 0.5 at r = 0.5.
  EXPECT_TRUE(project(CameraModelId::kFov, {100, 100, 50, 40, M_PI / 2}, {0.5, 0.0})
                  .isApprox(Eigen::Vector2d(100.0, 40.0), 1e-12));
  // theta = atan(0.5); theta_d = theta (1 + 0.1 theta^2).
  EXPECT_TRUE(project(CameraModelId::kSimpleRadialFisheye, {100, 50, 40, 0.1}, p)
                  .isApprox(Eigen::Vector2d(78.41687601022616, 77.88916801363489), 1e-12));
  // Thin prism: equidistant angle scaling, then u' += sx1 * theta^2.
  EXPECT_TRUE(project(CameraModelId::kThinPrismFisheye,
                      {100, 200, 50, 40, 0, 0, 0, 0, 0, 0, 0.1, 0},
                      p)
                  .isApprox(Eigen::Vector2d(79.96854759337, 114.18361744012898), 1e-12));
}

TEST(CameraModels, UnprojectionBeyondAFisheyesDomainIsNaN) {
  // With no coefficients the equidistant model reaches at most r_d = pi / 2 (90 degrees).
  const std::vector<double> params = {100, 100, 50, 40, 0, 0, 0, 0};
  const Eigen::Vector2d beyond(50 + 100 * 2.0, 40);
  EXPECT_FALSE(CamFromImg(CameraModelId::kOpenCvFisheye, params, beyond).allFinite());
}

TEST(CameraModels, NewerModelIdsAreRefusedByName) {
  try {
    CameraModelIdFromInt(12, "cameras.bin: camera 3: field 'model_id'");
    FAIL() << "model 12 accepted";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("cameras.bin: camera 3"), std::string::npos) << message;
    EXPECT_NE(message.find("SIMPLE_DIVISION"), std::string::npos) << message;
  }
  EXPECT_THROW(CameraModelIdFromInt(99, "x"), InputError);
  EXPECT_THROW(CameraModelIdFromInt(-1, "x"), InputError);
  // Ids near INT_MIN (found by fuzzing: a signed overflow under UBSan).
  EXPECT_THROW(CameraModelIdFromInt(std::numeric_limits<int>::min() + 1, "x"), InputError);
  EXPECT_THROW(CameraModelIdFromInt(std::numeric_limits<int>::min(), "x"), InputError);
  EXPECT_THROW(CameraModelIdFromInt(std::numeric_limits<int>::max(), "x"), InputError);
  try {
    CameraModelIdFromName("EUCM", "cameras.txt: line 4");
    FAIL() << "EUCM accepted";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("EUCM"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("newer"), std::string::npos);
  }
  EXPECT_THROW(CameraModelIdFromName("pinhole", "x"), InputError);  // names are case-sensitive
}

TEST(PixelConvention, TopLeftPixelCentreIsHalfAPixelInCOLMAPAndZeroInOpenCV) {
  EXPECT_EQ(PixelCentre(0, 0), Eigen::Vector2d(0.5, 0.5));
  EXPECT_EQ(PixelCentre(2, 7), Eigen::Vector2d(7.5, 2.5));  // (row, col) -> (x, y)
  EXPECT_EQ(OpenCvFromColmap(Eigen::Vector2d(0.5, 0.5)), Eigen::Vector2d(0.0, 0.0));
  EXPECT_EQ(ColmapFromOpenCv(Eigen::Vector2d(3.0, 4.0)), Eigen::Vector2d(3.5, 4.5));
  // A point exactly on the border between the first two pixels.
  EXPECT_EQ(OpenCvFromColmap(Eigen::Vector2d(1.0, 1.0)), Eigen::Vector2d(0.5, 0.5));
}

TEST(RescaledCamera, APointProjectsToItsPixelScaledForEveryModel) {
  // Halving the photo halves every pixel coordinate (COLMAP's corner-at-0 convention).
  for (CameraModelId model : SupportedCameraModels()) {
    Camera camera;
    camera.model = model;
    camera.width = 4000;
    camera.height = 3000;
    camera.params = ExampleCameraParams(model, 4000, 3000, 3500.0);
    const Camera half = RescaledCamera(camera, 2000, 1500);
    EXPECT_EQ(half.width, 2000u);
    EXPECT_EQ(half.height, 1500u);
    for (const Eigen::Vector2d& normalized :
         {Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.21, -0.13), Eigen::Vector2d(-0.4, 0.3)}) {
      const Eigen::Vector2d full = camera.ImgFromCam(normalized);
      const Eigen::Vector2d reduced = half.ImgFromCam(normalized);
      EXPECT_NEAR((reduced - 0.5 * full).norm(), 0.0, 1e-9) << CameraModelName(model);
    }
  }
  // Scales that differ along the axes: fx, fy and the principal point follow each.
  Camera pinhole;
  pinhole.model = CameraModelId::kPinhole;
  pinhole.width = 1000;
  pinhole.height = 500;
  pinhole.params = {900.0, 910.0, 500.0, 250.0};
  const Camera squeezed = RescaledCamera(pinhole, 500, 400);
  EXPECT_DOUBLE_EQ(squeezed.params[0], 450.0);
  EXPECT_DOUBLE_EQ(squeezed.params[1], 728.0);
  EXPECT_DOUBLE_EQ(squeezed.params[2], 250.0);
  EXPECT_DOUBLE_EQ(squeezed.params[3], 200.0);
}

TEST(LimitedImageSize, KeepsTheAspectAndLeavesSmallerPhotosAlone) {
  EXPECT_EQ(LimitedImageSize(4000, 3000, 2400), Eigen::Vector2i(2400, 1800));
  EXPECT_EQ(LimitedImageSize(3000, 4000, 2400), Eigen::Vector2i(1800, 2400));
  EXPECT_EQ(LimitedImageSize(640, 480, 2400), Eigen::Vector2i(640, 480));
  EXPECT_EQ(LimitedImageSize(4000, 3000, 0), Eigen::Vector2i(4000, 3000));
  EXPECT_EQ(LimitedImageSize(4001, 3, 1000), Eigen::Vector2i(1000, 1));
}

}  // namespace
}  // namespace raycarve
