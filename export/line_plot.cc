#include "export/line_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

namespace raycarve {
namespace exporter {
namespace {

const cv::Scalar kColours[] = {{200, 90, 30}, {40, 40, 220}, {40, 160, 40},
                               {160, 60, 160}, {30, 150, 220}, {100, 100, 100}};

std::string TickText(double value) {
  char text[32];
  if (std::abs(value) >= 1e6) {
    std::snprintf(text, sizeof(text), "%gM", value / 1e6);
  } else if (std::abs(value) >= 1e4) {
    std::snprintf(text, sizeof(text), "%gk", value / 1e3);
  } else {
    std::snprintf(text, sizeof(text), "%g", value);
  }
  return text;
}

}  // namespace

double TickSpacing(double max_value, int ticks) {
  if (!(max_value > 0.0) || ticks < 1) return 1.0;
  const double raw = max_value / ticks;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double step : {1.0, 2.0, 5.0}) {
    if (step * power >= raw) return step * power;
  }
  return 10.0 * power;
}

cv::Mat DrawLinePlot(const std::vector<PlotSeries>& series,
                     const PlotLabels& labels,
                     int width,
                     int height) {
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 90, right = 30, top = 50, bottom = 70;
  const int plot_width = width - left - right, plot_height = height - top - bottom;
  double x_max = 0.0, y_max = 0.0;
  for (const PlotSeries& s : series) {
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (std::isfinite(s.x[i])) x_max = std::max(x_max, s.x[i]);
      if (std::isfinite(s.y[i])) y_max = std::max(y_max, s.y[i]);
    }
  }
  const double x_tick = TickSpacing(x_max, 8), y_tick = TickSpacing(y_max, 6);
  x_max = std::max(x_tick, std::ceil(x_max / x_tick) * x_tick);
  y_max = std::max(y_tick, std::ceil(y_max / y_tick) * y_tick);
  auto to_pixel = [&](double x, double y) {
    return cv::Point(left + static_cast<int>(std::lround(x / x_max * plot_width)),
                     top + plot_height - static_cast<int>(std::lround(y / y_max * plot_height)));
  };
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const cv::Scalar grid(225, 225, 225), ink(40, 40, 40);
  for (double x = 0.0; x <= x_max * (1 + 1e-9); x += x_tick) {
    cv::line(image, to_pixel(x, 0), to_pixel(x, y_max), grid, 1);
    const std::string text = TickText(x);
    cv::putText(image, text, to_pixel(x, 0) + cv::Point(-4 * static_cast<int>(text.size()), 22),
                font, 0.45, ink, 1, cv::LINE_AA);
  }
  for (double y = 0.0; y <= y_max * (1 + 1e-9); y += y_tick) {
    cv::line(image, to_pixel(0, y), to_pixel(x_max, y), grid, 1);
    const std::string text = TickText(y);
    cv::putText(image, text, to_pixel(0, y) + cv::Point(-10 - 9 * static_cast<int>(text.size()), 5),
                font, 0.45, ink, 1, cv::LINE_AA);
  }
  cv::rectangle(image, to_pixel(0, y_max), to_pixel(x_max, 0), ink, 1);
  for (size_t k = 0; k < series.size(); ++k) {
    const cv::Scalar colour = kColours[k % (sizeof(kColours) / sizeof(kColours[0]))];
    const PlotSeries& s = series[k];
    std::vector<cv::Point> points;
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) points.push_back(to_pixel(s.x[i], s.y[i]));
    }
    if (points.size() >= 2) cv::polylines(image, points, false, colour, 2, cv::LINE_AA);
    if (points.size() == 1) cv::circle(image, points[0], 3, colour, cv::FILLED);
    const cv::Point legend(left + 15, top + 22 + 24 * static_cast<int>(k));
    cv::line(image, legend, legend + cv::Point(30, 0), colour, 3, cv::LINE_AA);
    cv::putText(image, s.name, legend + cv::Point(40, 5), font, 0.55, ink, 1, cv::LINE_AA);
  }
  int baseline = 0;
  const cv::Size title = cv::getTextSize(labels.title, font, 0.65, 1, &baseline);
  cv::putText(image, labels.title, cv::Point((width - title.width) / 2, 32), font, 0.65, ink, 1,
              cv::LINE_AA);
  const cv::Size x_label = cv::getTextSize(labels.x_axis, font, 0.55, 1, &baseline);
  cv::putText(image, labels.x_axis, cv::Point(left + (plot_width - x_label.width) / 2, height - 18),
              font, 0.55, ink, 1, cv::LINE_AA);
  // The y label, written horizontally and turned a quarter counter-clockwise.
  const cv::Size y_size = cv::getTextSize(labels.y_axis, font, 0.55, 1, &baseline);
  cv::Mat label(y_size.height + 8, y_size.width + 4, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(label, labels.y_axis, cv::Point(2, y_size.height + 2), font, 0.55, ink, 1,
              cv::LINE_AA);
  cv::Mat turned;
  cv::rotate(label, turned, cv::ROTATE_90_COUNTERCLOCKWISE);
  const int y0 = std::max(0, top + (plot_height - turned.rows) / 2);
  if (turned.cols <= left && y0 + turned.rows <= height) {
    turned.copyTo(image(cv::Rect(8, y0, turned.cols, turned.rows)));
  }
  return image;
}

}  // namespace exporter
}  // namespace raycarve
