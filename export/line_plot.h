#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace raycarve {
namespace exporter {

// One line of a plot: points (x[i], y[i]) joined in order.
struct PlotSeries {
  std::string name;
  std::vector<double> x;
  std::vector<double> y;
};

struct PlotLabels {
  std::string title;
  std::string x_axis;
  std::string y_axis;
};

// Draws the series on shared linear axes starting at zero (ticks at round numbers, a legend in
// the top-left corner, one colour per series) into a BGR image of `width` x `height`, ready for
// cv::imwrite. Series may be empty; non-finite points are skipped.
cv::Mat DrawLinePlot(const std::vector<PlotSeries>& series,
                     const PlotLabels& labels,
                     int width = 960,
                     int height = 600);

// A round tick spacing for an axis from 0 to `max_value` with about `ticks` ticks (1, 2 or 5
// times a power of ten).
double TickSpacing(double max_value, int ticks);

}  // namespace exporter
}  // namespace raycarve
