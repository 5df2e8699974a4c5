#include "calib/colour_calibration.h"

#include <algorithm>
#include <cstdio>

#include <gtest/gtest.h>

#include "samples/synthetic_scene.h"
#include "tests/scene_options.h"

namespace raycarve {
namespace {

std::vector<CalibratedView> Views(const SyntheticScene& scene) {
  std::vector<CalibratedView> views;
  for (const auto& [image_id, image] : scene.reconstruction.images) {
    views.push_back(MakeCalibratedView(scene.reconstruction.cameras.at(image.camera_id), image,
                                       scene.photos.at(image_id).clone(), image.name));
  }
  return views;
}

// Mean absolute RGB difference between two views' images.
double MeanDifference(const CalibratedView& a, const CalibratedView& b) {
  cv::Mat difference;
  cv::absdiff(a.image, b.image, difference);
  const cv::Scalar mean = cv::mean(difference);
  return (mean[0] + mean[1] + mean[2]) / 3.0;
}

// Eight photos of 200x150 with 3000 candidate sparse points.
SyntheticSceneOptions EightPhotos() { return testing::SceneOptions(8, 200, 150, false, 3000); }

TEST(ColourCalibration, UndoesKnownExposureAndWhiteBalanceChangesOfSomePhotos) {
  const SyntheticScene scene = GenerateSyntheticScene(EightPhotos());
  const std::vector<CalibratedView> original = Views(scene);
  std::vector<CalibratedView> changed = Views(scene);
  // Photo 2 darker and bluish, photo 5 brighter with a red cast (kept inside 0-255 mostly).
  const struct {
    int view;
    Eigen::Vector3d gain, offset;
  } changes[] = {{2, {0.75, 0.8, 0.9}, {5.0, 0.0, 12.0}}, {5, {1.1, 1.0, 0.95}, {-8.0, 4.0, 0.0}}};
  for (const auto& change : changes) {
    cv::Mat& image = changed[change.view].image;
    for (int row = 0; row < image.rows; ++row) {
      for (int col = 0; col < image.cols; ++col) {
        cv::Vec3b& p = image.at<cv::Vec3b>(row, col);
        for (int c = 0; c < 3; ++c) {
          p[c] = cv::saturate_cast<uint8_t>(change.gain[c] * p[c] + change.offset[c]);
        }
      }
    }
  }
  const double before = MeanDifference(changed[2], original[2]) + MeanDifference(changed[5], original[5]);

  const ColourCalibration calibration = EstimateColourCalibration(scene.reconstruction, changed);
  std::printf("%s\n", calibration.Summary().c_str());
  EXPECT_GT(calibration.points_used, 200);
  // The unchanged photos disagree too (points on texture edges, sampling): the correction brings
  // the spread back to about theirs. Measured: 20.6 changed, 14.8 corrected.
  const double baseline = EstimateColourCalibration(scene.reconstruction, original).spread_before;
  std::printf("spread of the unchanged photos %.2f\n", baseline);
  EXPECT_LT(calibration.spread_after, 0.8 * calibration.spread_before);
  EXPECT_LT(calibration.spread_after, baseline + 1.0);
  ASSERT_EQ(calibration.corrections.size(), changed.size());
  // The recovered gains follow the applied ones up to the common scale the data cannot tell.
  EXPECT_NEAR(calibration.corrections[2].gain.x() / calibration.corrections[0].gain.x(), 0.75, 0.08);
  EXPECT_NEAR(calibration.corrections[5].gain.x() / calibration.corrections[0].gain.x(), 1.1, 0.08);

  ApplyColourCalibration(calibration, &changed);
  const double after = MeanDifference(changed[2], original[2]) + MeanDifference(changed[5], original[5]);
  std::printf("mean |changed - original| over the two photos: %.2f before, %.2f after\n", before, after);
  EXPECT_LT(after, 0.4 * before);
  // Photos that were not changed stay nearly as they were.
  EXPECT_LT(MeanDifference(changed[0], original[0]), 3.0);
}

TEST(ColourCalibration, PaysWhereExposuresDifferNotWherePhotosAgree) {
  // The generated scene as an automatic exposure would take it (every photo's gain 1 +- 0.3),
  // and as it is: the correction must halve the spread in the first, and does not in the second
  // (the points' remaining disagreement is texture edges and sampling, no exposure).
  SyntheticSceneOptions options = EightPhotos();
  const SyntheticScene alike = GenerateSyntheticScene(options);
  options.exposure_spread = 0.3;
  const SyntheticScene exposed = GenerateSyntheticScene(options);
  const ColourCalibration varying = EstimateColourCalibration(exposed.reconstruction, Views(exposed));
  const ColourCalibration same = EstimateColourCalibration(alike.reconstruction, Views(alike));
  std::printf("exposures varying: %s\nalike: %s\n", varying.Summary().c_str(),
              same.Summary().c_str());
  EXPECT_TRUE(ColourCalibrationPays(varying));
  EXPECT_FALSE(ColourCalibrationPays(same));
  // The gains found follow the photos' exposures (up to the common scale).
  double most = 0.0, least = 1e9;
  for (const ColourCorrection& correction : varying.corrections) {
    most = std::max(most, correction.gain.mean());
    least = std::min(least, correction.gain.mean());
  }
  EXPECT_GT(most / least, 1.5);  // the exposures span 0.7-1.3, up to the clipping of bright pixels

  ColourCalibrationMode mode = ColourCalibrationMode::kOff;
  EXPECT_TRUE(ColourCalibrationModeFromString("auto", &mode));
  EXPECT_EQ(mode, ColourCalibrationMode::kAuto);
  EXPECT_TRUE(ColourCalibrationModeFromString("1", &mode));
  EXPECT_EQ(mode, ColourCalibrationMode::kOn);
  EXPECT_TRUE(ColourCalibrationModeFromString("false", &mode));
  EXPECT_EQ(mode, ColourCalibrationMode::kOff);
  EXPECT_FALSE(ColourCalibrationModeFromString("yes", &mode));
}

TEST(ColourCalibration, WithoutSharedPointsNothingChanges) {
  const SyntheticScene scene = GenerateSyntheticScene(testing::SceneOptions(3, 64, 48));
  std::vector<CalibratedView> views = Views(scene);
  const ColourCalibration calibration = EstimateColourCalibration(scene.reconstruction, views);
  EXPECT_EQ(calibration.points_used, 0);
  for (const ColourCorrection& correction : calibration.corrections) {
    EXPECT_EQ(correction.gain, Eigen::Vector3d::Ones());
    EXPECT_EQ(correction.offset, Eigen::Vector3d::Zero());
  }
}

}  // namespace
}  // namespace raycarve
