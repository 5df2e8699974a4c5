#include "carve/consistency.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace raycarve {
namespace {

ViewColourStats View(int view, std::initializer_list<Eigen::Vector3d> pixels) {
  ViewColourStats stats;
  stats.view = view;
  for (const Eigen::Vector3d& p : pixels) stats.Add(p);
  return stats;
}

TEST(MeanColourTest, WeightsTheDistanceOfEachViewsMeanByItsPixelCount) {
  // View 0: three pixels of (100, 0, 0); view 1: one pixel of (0, 0, 0).
  // m = (300, 0, 0) / 4 = (75, 0, 0); |m0 - m| = 25, |m1 - m| = 75; error = (3*25 + 75) / 4 = 37.5.
  const std::vector<ViewColourStats> views = {
      View(0, {{100, 0, 0}, {100, 0, 0}, {100, 0, 0}}), View(1, {{0, 0, 0}})};
  const Consistency tight = ConsistencyTest(ConsistencyMethod::kMeanColour, 37.0, 2).Evaluate(views);
  EXPECT_TRUE(tight.judged);
  EXPECT_DOUBLE_EQ(tight.error, 37.5);
  EXPECT_FALSE(tight.consistent);
  EXPECT_EQ(tight.colour, Eigen::Vector3d(75, 0, 0));
  EXPECT_EQ(tight.num_views, 2);
  EXPECT_EQ(tight.num_pixels, 4);
  EXPECT_TRUE(ConsistencyTest(ConsistencyMethod::kMeanColour, 38.0, 2).Evaluate(views).consistent);
}

TEST(MeanColourTest, IgnoresVariationWithinAViewAndUsesTheEuclideanNorm) {
  // Both views average to (50, 50, 50) although their pixels differ a lot: error 0.
  const std::vector<ViewColourStats> same_means = {View(0, {{0, 0, 0}, {100, 100, 100}}),
                                                   View(1, {{50, 50, 50}})};
  EXPECT_DOUBLE_EQ(ConsistencyTest(ConsistencyMethod::kMeanColour, 0.0, 2).Evaluate(same_means).error, 0.0);
  // Means (0,0,0) and (30,40,0), one pixel each: |m_j - m| = 25 each (a 3-4-5 triangle, halved).
  const std::vector<ViewColourStats> apart = {View(0, {{0, 0, 0}}), View(1, {{30, 40, 0}})};
  EXPECT_DOUBLE_EQ(ConsistencyTest(ConsistencyMethod::kMeanColour, 0.0, 2).Evaluate(apart).error, 25.0);
}

TEST(MeanColourTest, TheViewCountCorrectionPutsFewViewsOnTheScaleOfMany) {
  // Two views apart by (30, 40, 0): 25 uncorrected, 25 sqrt(2) corrected.
  const std::vector<ViewColourStats> two = {View(0, {{0, 0, 0}}), View(1, {{30, 40, 0}})};
  EXPECT_DOUBLE_EQ(ConsistencyTest(ConsistencyMethod::kMeanColour, 0.0, 2, 0.0, true).Evaluate(two).error,
                   25.0 * std::sqrt(2.0));
  // One colour seen through noise (each view's mean off by a Gaussian of 10 per channel): the
  // mean error over 4000 voxels seen by two views is sqrt(1/2) of that seen by twelve uncorrected
  // (sqrt(11/12) for twelve), and the same corrected.
  std::mt19937 random(5);
  std::normal_distribution<double> noise(0.0, 10.0);
  const auto mean_error = [&](int k, bool correct) {
    const ConsistencyTest test(ConsistencyMethod::kMeanColour, 0.0, 2, 0.0, correct);
    double sum = 0.0;
    for (int trial = 0; trial < 4000; ++trial) {
      std::vector<ViewColourStats> views;
      for (int v = 0; v < k; ++v) {
        views.push_back(View(v, {{100 + noise(random), 100 + noise(random), 100 + noise(random)}}));
      }
      sum += test.Evaluate(views).error;
    }
    return sum / 4000;
  };
  EXPECT_NEAR(mean_error(2, false) / mean_error(12, false), std::sqrt(0.5 / (11.0 / 12.0)), 0.03);
  EXPECT_NEAR(mean_error(2, true) / mean_error(12, true), 1.0, 0.03);
  // Three views (0, 0, 0), (0, 0, 0), (90, 0, 0): mean (30, 0, 0), distances 30, 30, 60: 40
  // uncorrected, 40 sqrt(3/2) corrected; the standard deviation test is not affected.
  const std::vector<ViewColourStats> three = {View(0, {{0, 0, 0}}), View(1, {{0, 0, 0}}),
                                              View(2, {{90, 0, 0}})};
  EXPECT_DOUBLE_EQ(ConsistencyTest(ConsistencyMethod::kMeanColour, 0.0, 2).Evaluate(three).error, 40.0);
  EXPECT_DOUBLE_EQ(
      ConsistencyTest(ConsistencyMethod::kMeanColour, 0.0, 2, 0.0, true).Evaluate(three).error,
      40.0 * std::sqrt(1.5));
  EXPECT_DOUBLE_EQ(
      ConsistencyTest(ConsistencyMethod::kStandardDeviation, 0.0, 2, 0.0, true).Evaluate(three).error,
      ConsistencyTest(ConsistencyMethod::kStandardDeviation, 0.0, 2).Evaluate(three).error);
}

TEST(StandardDeviationTest, PoolsAllPixelsOfAllViews) {
  // Red channel values 0 and 100 (std 50), green and blue constant: RMS over channels 50/sqrt(3).
  const std::vector<ViewColourStats> views = {View(0, {{0, 7, 7}}), View(1, {{100, 7, 7}})};
  const Consistency result =
      ConsistencyTest(ConsistencyMethod::kStandardDeviation, 28.0, 2).Evaluate(views);
  EXPECT_NEAR(result.error, 50.0 / std::sqrt(3.0), 1e-9);
  EXPECT_FALSE(result.consistent);
  EXPECT_TRUE(ConsistencyTest(ConsistencyMethod::kStandardDeviation, 29.0, 2).Evaluate(views).consistent);
  // Unlike the mean test, variation inside one view counts.
  const std::vector<ViewColourStats> noisy = {View(0, {{0, 0, 0}, {100, 100, 100}}),
                                              View(1, {{50, 50, 50}})};
  EXPECT_GT(ConsistencyTest(ConsistencyMethod::kStandardDeviation, 0.0, 2).Evaluate(noisy).error, 40.0);
}

TEST(ConsistencyTest, VoxelsSeenByFewerThanMinViewsAreKeptUnjudged) {
  const std::vector<ViewColourStats> one_view = {View(3, {{0, 0, 0}, {255, 255, 255}})};
  for (ConsistencyMethod method : {ConsistencyMethod::kMeanColour, ConsistencyMethod::kStandardDeviation}) {
    const Consistency result = ConsistencyTest(method, 0.0, 2).Evaluate(one_view);
    EXPECT_FALSE(result.judged);
    EXPECT_TRUE(result.consistent);
    EXPECT_EQ(result.colour, Eigen::Vector3d(127.5, 127.5, 127.5));
  }
  const Consistency unseen = ConsistencyTest(ConsistencyMethod::kMeanColour, 0.0, 2).Evaluate({});
  EXPECT_TRUE(unseen.consistent);
  EXPECT_EQ(unseen.num_pixels, 0);
  ConsistencyMethod method;
  EXPECT_TRUE(ConsistencyMethodFromString("standard_deviation", &method));
  EXPECT_EQ(method, ConsistencyMethod::kStandardDeviation);
  EXPECT_FALSE(ConsistencyMethodFromString("median", &method));
}

// A voxel across a black-and-white edge: each view sees both colours, in different shares, so
// their means disagree although it is the true surface. The spread floor holds the threshold to at
// least the views' own spread; a threshold already above it is left as it is, and a voxel whose
// views each see one plain colour gets no floor.
TEST(ConsistencyTest, TheSpreadFloorRaisesALowThresholdToTheVoxelsWithinViewSpread) {
  const Eigen::Vector3d black(0, 0, 0), white(255, 255, 255);
  const std::vector<ViewColourStats> edge = {View(0, {black, white, white, white}),
                                             View(1, {black, black, black, white})};
  const double spread = ConsistencyTest::WithinViewSpread(edge);
  // Each view: 255 sqrt(3/16) a channel, over three channels.
  EXPECT_NEAR(spread, 3.0 * 255.0 / 4.0, 1e-9);
  const Consistency low = ConsistencyTest(ConsistencyMethod::kMeanColour, 5.0, 2).Evaluate(edge);
  EXPECT_FALSE(low.consistent);
  EXPECT_LT(low.error, spread);
  const Consistency floored =
      ConsistencyTest(ConsistencyMethod::kMeanColour, 5.0, 2, 0.0, false, 1.0).Evaluate(edge);
  EXPECT_TRUE(floored.consistent);
  EXPECT_DOUBLE_EQ(floored.threshold, spread);
  EXPECT_DOUBLE_EQ(floored.error, low.error);
  // Above the spread: the threshold as it is (where the adaptive allowance would add to it).
  EXPECT_DOUBLE_EQ(ConsistencyTest(ConsistencyMethod::kMeanColour, 400.0, 2, 0.0, false, 1.0)
                       .Evaluate(edge)
                       .threshold,
                   400.0);
  EXPECT_DOUBLE_EQ(
      ConsistencyTest(ConsistencyMethod::kMeanColour, 400.0, 2, 1.0).Evaluate(edge).threshold,
      400.0 + spread);
  // Plain views of different colours (empty space in front of a background): no spread, no floor.
  const std::vector<ViewColourStats> plain = {View(0, {black, black}), View(1, {white, white})};
  const Consistency apart =
      ConsistencyTest(ConsistencyMethod::kMeanColour, 5.0, 2, 0.0, false, 1.0).Evaluate(plain);
  EXPECT_DOUBLE_EQ(apart.threshold, 5.0);
  EXPECT_FALSE(apart.consistent);
}

}  // namespace
}  // namespace raycarve
