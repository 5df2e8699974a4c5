#include "export/line_plot.h"

#include <gtest/gtest.h>

namespace raycarve {
namespace exporter {
namespace {

TEST(LinePlot, TickSpacingIsOneTwoOrFiveTimesAPowerOfTen) {
  EXPECT_DOUBLE_EQ(TickSpacing(10.0, 5), 2.0);
  EXPECT_DOUBLE_EQ(TickSpacing(16.5, 8), 5.0);
  EXPECT_DOUBLE_EQ(TickSpacing(934784.0, 6), 200000.0);
  EXPECT_DOUBLE_EQ(TickSpacing(0.07, 7), 0.01);
  EXPECT_DOUBLE_EQ(TickSpacing(0.0, 5), 1.0);
}

// Pixels of a BGR colour in the plot area.
int CountColour(const cv::Mat& image, const cv::Vec3b& colour) {
  int count = 0;
  for (int row = 0; row < image.rows; ++row) {
    for (int col = 0; col < image.cols; ++col) count += image.at<cv::Vec3b>(row, col) == colour;
  }
  return count;
}

TEST(LinePlot, DrawsEachSeriesInItsOwnColourWhereItsPointsAre) {
  PlotSeries rising{"rising", {0, 1, 2, 3, 4}, {0, 10, 20, 30, 40}};
  PlotSeries flat{"flat", {0, 4}, {5, 5}};
  const cv::Mat plot = DrawLinePlot({rising, flat}, {"title", "x", "y"}, 600, 400);
  ASSERT_EQ(plot.type(), CV_8UC3);
  EXPECT_EQ(plot.cols, 600);
  EXPECT_EQ(plot.rows, 400);
  const cv::Vec3b first(200, 90, 30), second(40, 40, 220);
  EXPECT_GT(CountColour(plot, first), 300);
  EXPECT_GT(CountColour(plot, second), 300);
  // The rising line ends at the top right of the plot area (x 4 of 4, y 40 of 40), the flat line
  // stays in the lower part: its colour is absent from the top half's plot area.
  const cv::Mat top = plot(cv::Rect(150, 50, 400, 120));
  EXPECT_GT(CountColour(top, first), 20);
  EXPECT_EQ(CountColour(top, second), 0);
}

TEST(LinePlot, EmptyAndNonFiniteSeriesStillGiveAPlot) {
  PlotSeries broken{"broken", {0, NAN, 2}, {1, 2, INFINITY}};
  const cv::Mat plot = DrawLinePlot({broken, PlotSeries{}}, {"t", "x", "y"});
  EXPECT_EQ(plot.cols, 960);
  EXPECT_EQ(plot.rows, 600);
}

}  // namespace
}  // namespace exporter
}  // namespace raycarve
