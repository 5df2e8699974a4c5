#include "export/point_renderer.h"

#include <cmath>

#include <gtest/gtest.h>

#include "export/holdout_score.h"
#include "tests/test_support.h"

namespace raycarve {
namespace exporter {
namespace {

// A 100x80 pinhole view at the origin looking down +z, f = 100, principal point (50, 40).
CalibratedView View() {
  CalibratedView view = testing::PinholeViewAtOrigin(100, 80, 100);
  view.image = cv::Mat(80, 100, CV_8UC3, cv::Scalar(10, 20, 30));
  return view;
}

ColouredPoint Point(float x, float y, float z, uint8_t r) {
  ColouredPoint point;
  point.xyz = Eigen::Vector3f(x, y, z);
  point.rgb << r, 0, 0;
  return point;
}

TEST(RenderPoints, SplatsCoverTheProjectedCubeAndTheNearestPointWins) {
  const CalibratedView view = View();
  // At depth 10 a 0.4-wide cube projects to 4 px: centre (50, 40) covers centres 48.5 .. 51.5.
  const Rendering one = RenderPoints({Point(0, 0, 10, 200)}, view, 0.4);
  EXPECT_EQ(cv::countNonZero(one.silhouette), 16);
  EXPECT_EQ(one.silhouette.at<uint8_t>(38, 48), 255);
  EXPECT_EQ(one.silhouette.at<uint8_t>(41, 51), 255);
  EXPECT_EQ(one.silhouette.at<uint8_t>(42, 52), 0);
  EXPECT_EQ(one.image.at<cv::Vec3b>(40, 50), cv::Vec3b(200, 0, 0));
  EXPECT_FLOAT_EQ(one.depth.at<float>(40, 50), 10.0f);
  // A point behind it, drawn second or first, is hidden; one behind the camera is not drawn.
  for (const auto& points : {std::vector<ColouredPoint>{Point(0, 0, 10, 200), Point(0, 0, 20, 90)},
                             std::vector<ColouredPoint>{Point(0, 0, 20, 90), Point(0, 0, 10, 200)}}) {
    EXPECT_EQ(RenderPoints(points, view, 0.4).image.at<cv::Vec3b>(40, 50), cv::Vec3b(200, 0, 0));
  }
  EXPECT_EQ(cv::countNonZero(RenderPoints({Point(0, 0, -5, 9)}, view, 0.4).silhouette), 0);
  // A tiny point still covers its own pixel.
  EXPECT_EQ(cv::countNonZero(RenderPoints({Point(0.001f, 0.001f, 10, 9)}, view, 1e-6).silhouette), 1);
}

TEST(HoldoutScore, PsnrOverTheSilhouettesAndTheirIou) {
  CalibratedView view = View();
  Rendering rendering;
  rendering.image = view.image.clone();
  rendering.silhouette = cv::Mat(80, 100, CV_8UC1, cv::Scalar(0));
  rendering.silhouette(cv::Rect(10, 10, 20, 20)).setTo(255);
  // Without a mask every valid pixel is scored; identical pixels give an infinite PSNR.
  HoldoutScore score = ScoreRendering(rendering, view);
  EXPECT_EQ(score.scored_pixels, 8000);
  EXPECT_TRUE(std::isinf(score.psnr));
  EXPECT_EQ(score.silhouette_iou, -1.0);
  // A mask of the same square shifted by 10 px: IoU 200 / 600; scored pixels the union, 600.
  view.mask = cv::Mat(80, 100, CV_8UC1, cv::Scalar(0));
  view.mask(cv::Rect(20, 10, 20, 20)).setTo(255);
  rendering.image.setTo(cv::Scalar(10 + 51, 20, 30));  // off by 51 in red everywhere
  score = ScoreRendering(rendering, view);
  EXPECT_EQ(score.scored_pixels, 600);
  EXPECT_NEAR(score.silhouette_iou, 200.0 / 600.0, 1e-12);
  // MSE = 51^2 / 3 per channel: PSNR = 10 log10(255^2 * 3 / 51^2).
  EXPECT_NEAR(score.psnr, 10.0 * std::log10(255.0 * 255.0 * 3.0 / (51.0 * 51.0)), 1e-9);
  EXPECT_EQ(SideBySide(rendering, view).size(), cv::Size(300, 80));
}

TEST(HoldoutScore, SsimIsOneForThePhotoAndPrefersItsPatternShiftedToAFlatMean) {
  CalibratedView view = View();  // 100x80
  // Vertical stripes 6 px wide, 40 and 200 in every channel.
  const auto stripes = [](int shift) {
    cv::Mat image(80, 100, CV_8UC3);
    for (int row = 0; row < 80; ++row) {
      for (int col = 0; col < 100; ++col) {
        const uint8_t v = ((col + shift) / 6) % 2 ? 200 : 40;
        image.at<cv::Vec3b>(row, col) = cv::Vec3b(v, v, v);
      }
    }
    return image;
  };
  view.image = stripes(0);
  Rendering rendering;
  rendering.silhouette = cv::Mat(80, 100, CV_8UC1, cv::Scalar(255));
  rendering.image = view.image.clone();
  EXPECT_NEAR(ScoreRendering(rendering, view).ssim, 1.0, 1e-6);
  // The stripes two pixels off against their flat mean (120): PSNR prefers the flat mean (a third
  // of the pixels off by 160 against all of them by 80), SSIM the stripes.
  rendering.image = stripes(2);
  const HoldoutScore shifted = ScoreRendering(rendering, view);
  rendering.image.setTo(cv::Scalar(120, 120, 120));
  const HoldoutScore flat = ScoreRendering(rendering, view);
  EXPECT_LT(shifted.psnr, flat.psnr);
  EXPECT_GT(shifted.ssim, 3.0 * flat.ssim);
  EXPECT_LT(flat.ssim, 0.05);
  // Scored over the union of silhouettes and mask, as PSNR: a mask on the left half, drawn
  // exactly there and flat elsewhere, scores the left half only.
  view.mask = cv::Mat(80, 100, CV_8UC1, cv::Scalar(0));
  view.mask(cv::Rect(0, 0, 40, 80)).setTo(255);
  rendering.silhouette.setTo(0);
  rendering.silhouette(cv::Rect(0, 0, 40, 80)).setTo(255);
  rendering.image = view.image.clone();
  rendering.image(cv::Rect(50, 0, 50, 80)).setTo(cv::Scalar(120, 120, 120));
  EXPECT_NEAR(ScoreRendering(rendering, view).ssim, 1.0, 1e-6);
}

TEST(HoldoutScore, BlockMeansScoreWhatOneColourPerBlockCanCarry) {
  CalibratedView view = View();  // 100x80
  // 2x2 squares of one colour each: 2x2 blocks lose nothing.
  for (int row = 0; row < 80; ++row) {
    for (int col = 0; col < 100; ++col) {
      view.image.at<cv::Vec3b>(row, col) =
          ((row / 2 + col / 2) % 2) ? cv::Vec3b(200, 100, 0) : cv::Vec3b(40, 100, 0);
    }
  }
  EXPECT_TRUE(std::isinf(BlockMeanPsnr(view, 2)));
  // 4x4 blocks hold two of each colour: every pixel is 80 from the block's mean in red.
  // MSE = 80^2 / 3 per channel: PSNR = 10 log10(255^2 * 3 / 80^2).
  EXPECT_NEAR(BlockMeanPsnr(view, 4), 10.0 * std::log10(255.0 * 255.0 * 3.0 / (80.0 * 80.0)), 1e-9);
  // Blocks of 64: the last column of blocks is 36 pixels wide and the last row 16 high, each its
  // own block; four uniform quadrants split there lose nothing.
  cv::Mat quadrants = view.image.clone();
  quadrants(cv::Rect(0, 0, 64, 64)).setTo(cv::Scalar(10, 20, 30));
  quadrants(cv::Rect(64, 0, 36, 64)).setTo(cv::Scalar(250, 20, 30));
  quadrants(cv::Rect(0, 64, 64, 16)).setTo(cv::Scalar(10, 220, 30));
  quadrants(cv::Rect(64, 64, 36, 16)).setTo(cv::Scalar(10, 20, 230));
  CalibratedView split = view;
  split.image = quadrants;
  EXPECT_TRUE(std::isinf(BlockMeanPsnr(split, 64)));
  EXPECT_TRUE(std::isfinite(BlockMeanPsnr(split, 65)));
  // Only the mask is scored: a mask over the left 20 columns, where the image is made uniform,
  // scores infinite whatever the rest holds.
  view.mask = cv::Mat(80, 100, CV_8UC1, cv::Scalar(0));
  view.mask(cv::Rect(0, 0, 20, 80)).setTo(255);
  view.image(cv::Rect(0, 0, 20, 80)).setTo(cv::Scalar(7, 8, 9));
  EXPECT_TRUE(std::isinf(BlockMeanPsnr(view, 4)));
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
