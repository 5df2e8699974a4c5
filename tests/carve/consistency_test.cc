#include "carve/consistency.h"

#include <cmath>

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

}  // namespace
}  // namespace raycarve
