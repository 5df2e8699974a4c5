#include "calib/undistortion.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "calib/pixel.h"
#include "samples/synthetic_scene.h"
#include "tests/test_support.h"

namespace raycarve {
namespace {

constexpr int kWidth = 240;
constexpr int kHeight = 180;
constexpr double kLineU = 0.22;   // the vertical line u = kLineU in normalised coordinates
constexpr double kLineV = -0.17;  // the horizontal line v = kLineV
// Bilinear resampling of a sampled line profile (with cv::remap's 1/32-pixel fixed-point
// coordinates) moves its centroid by up to ~0.13 px depending on the sub-pixel phase (measured);
// on average it stays put. A pixel-convention slip would be a 0.5 px bias, an unremoved
// distortion several pixels (see the test below).
constexpr double kTolerancePx = 0.2;
constexpr double kBiasTolerancePx = 0.05;

Camera DistortedCamera(CameraModelId model) {
  Camera camera =
      testing::MakeCamera(1, model, kWidth, kHeight, ExampleCameraParams(model, kWidth, kHeight, 0.8 * kWidth));
  // Stronger radial distortion where the model has a k1 right after the intrinsics.
  if (model == CameraModelId::kOpenCv || model == CameraModelId::kFullOpenCv) camera.params[4] = -0.3;
  if (model == CameraModelId::kSimpleRadial || model == CameraModelId::kRadial) camera.params[3] = -0.3;
  return camera;
}

// A synthetic photo through `camera` of one bright line drawn in the normalised image plane: the
// line u = value (axis 0) or v = value (axis 1), with a smooth triangular profile two pinhole
// pixels wide on each side, so that its centroid is well defined at sub-pixel precision.
cv::Mat RenderLine(const Camera& camera, int axis, double value) {
  cv::Mat photo(kHeight, kWidth, CV_8UC3, cv::Scalar::all(0));
  const double focal = axis == 0 ? camera.FocalLengthX() : camera.FocalLengthY();
  for (int row = 0; row < kHeight; ++row) {
    for (int col = 0; col < kWidth; ++col) {
      const Eigen::Vector2d uv = camera.CamFromImg(PixelCentre(row, col));
      const double distance_px = std::abs(uv[axis] - value) * focal;
      const double intensity = std::max(0.0, 1.0 - distance_px / 2.0);
      photo.at<cv::Vec3b>(row, col) = cv::Vec3b::all(static_cast<uint8_t>(std::lround(250 * intensity)));
    }
  }
  return photo;
}

// Per row, the intensity centroid (OpenCV column) of the vertical line near column `guess`.
std::vector<double> ColumnCentroids(const cv::Mat& photo, const cv::Mat& valid, double guess) {
  std::vector<double> centroids;
  const int centre = static_cast<int>(std::lround(guess));
  for (int row = 0; row < photo.rows; ++row) {
    // Away from the horizontal line, and with the whole window on valid pixels.
    double sum = 0.0, weighted = 0.0;
    bool usable = true;
    for (int col = centre - 8; col <= centre + 8; ++col) {
      if (col < 0 || col >= photo.cols || (!valid.empty() && valid.at<uint8_t>(row, col) == 0)) {
        usable = false;
        break;
      }
      const double w = photo.at<cv::Vec3b>(row, col)[0];
      sum += w;
      weighted += w * col;
    }
    if (usable && sum > 100.0) centroids.push_back(weighted / sum);
  }
  return centroids;
}

double MeanDeviation(const std::vector<double>& values, double expected) {
  double sum = 0.0;
  for (double v : values) sum += v - expected;
  return sum / values.size();
}

double MaxDeviation(const std::vector<double>& values, double expected) {
  double worst = 0.0;
  for (double v : values) worst = std::max(worst, std::abs(v - expected));
  return worst;
}

TEST(Undistortion, StraightLinesComeOutStraightWhereThePinholeModelPutsThem) {
  for (CameraModelId model : SupportedCameraModels()) {
    if (!CameraModelHasDistortion(model)) continue;
    SCOPED_TRACE(CameraModelName(model));
    const Camera camera = DistortedCamera(model);
    const UndistortionMaps maps = BuildUndistortionMaps(camera);
    cv::Mat undistorted, valid;
    UndistortImage(maps, RenderLine(camera, 0, kLineU), &undistorted, &valid);

    const Camera& pinhole = maps.pinhole;
    const double expected_column =
        OpenCvFromColmap(pinhole.ImgFromCam(Eigen::Vector2d(kLineU, 0.0))).x();
    const std::vector<double> straight = ColumnCentroids(undistorted, valid, expected_column);
    ASSERT_GT(straight.size(), kHeight / 2u);
    EXPECT_LT(MaxDeviation(straight, expected_column), kTolerancePx);
    EXPECT_LT(std::abs(MeanDeviation(straight, expected_column)), kBiasTolerancePx);

    // The horizontal line, through the transposed images.
    const double expected_row =
        OpenCvFromColmap(pinhole.ImgFromCam(Eigen::Vector2d(0.0, kLineV))).y();
    UndistortImage(maps, RenderLine(camera, 1, kLineV), &undistorted, &valid);
    const std::vector<double> straight_rows =
        ColumnCentroids(undistorted.t(), valid.t(), expected_row);
    ASSERT_GT(straight_rows.size(), kWidth / 2u);
    EXPECT_LT(MaxDeviation(straight_rows, expected_row), kTolerancePx);
    EXPECT_LT(std::abs(MeanDeviation(straight_rows, expected_row)), kBiasTolerancePx);
  }
}

TEST(Undistortion, TheDistortedLinesAreVisiblyCurvedSoTheCheckCanFail) {
  const Camera camera = DistortedCamera(CameraModelId::kOpenCv);
  const cv::Mat distorted = RenderLine(camera, 0, kLineU);
  const double expected_column =
      OpenCvFromColmap(PinholeCameraFor(camera).ImgFromCam(Eigen::Vector2d(kLineU, 0.0))).x();
  // Search the distorted photo around the same column: the line bends away from it.
  const std::vector<double> curved = ColumnCentroids(distorted, cv::Mat(), expected_column);
  ASSERT_GT(curved.size(), 20u);
  double lowest = 1e9, highest = -1e9;
  for (double c : curved) {
    lowest = std::min(lowest, c);
    highest = std::max(highest, c);
  }
  EXPECT_GT(highest - lowest, 2.0);
}

TEST(Undistortion, PinholeCameraMapsToItselfAndEveryPixelIsValid) {
  Camera camera;
  camera.model = CameraModelId::kPinhole;
  camera.width = 32;
  camera.height = 24;
  camera.params = {30, 31, 16.2, 11.9};
  const UndistortionMaps maps = BuildUndistortionMaps(camera);
  for (int row = 0; row < 24; ++row) {
    for (int col = 0; col < 32; ++col) {
      EXPECT_NEAR(maps.map_x.at<float>(row, col), col, 1e-4);
      EXPECT_NEAR(maps.map_y.at<float>(row, col), row, 1e-4);
    }
  }
  cv::Mat photo(24, 32, CV_8UC3);
  cv::randu(photo, 0, 255);
  cv::Mat undistorted, valid;
  UndistortImage(maps, photo, &undistorted, &valid);
  EXPECT_EQ(cv::countNonZero(valid), 32 * 24);
  EXPECT_EQ(cv::norm(undistorted, photo, cv::NORM_INF), 0.0);
}

TEST(Undistortion, PixelsBeyondTheDistortedFrameAreMarkedInvalid) {
  // Strong pincushion: the pinhole view's corners lie outside the distorted photo.
  Camera camera;
  camera.model = CameraModelId::kSimpleRadial;
  camera.width = 64;
  camera.height = 48;
  camera.params = {40, 32, 24, 0.5};
  const UndistortionMaps maps = BuildUndistortionMaps(camera);
  cv::Mat photo(48, 64, CV_8UC3, cv::Scalar::all(200));
  cv::Mat undistorted, valid;
  UndistortImage(maps, photo, &undistorted, &valid);
  EXPECT_EQ(valid.at<uint8_t>(24, 32), 255);
  EXPECT_EQ(valid.at<uint8_t>(0, 0), 0);
  EXPECT_EQ(undistorted.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
}

}  // namespace
}  // namespace raycarve
