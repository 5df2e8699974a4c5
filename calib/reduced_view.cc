// A photo as the distant and ground pixels' test judges it: calib/reduced_view.h.
#include "calib/reduced_view.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "calib/pixel.h"

namespace raycarve {

cv::Mat Grey(const ReducedView& g) {
  cv::Mat rgb, grey;
  g.rgb.convertTo(rgb, CV_32FC3);
  cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
  return grey;
}

ReducedView ReducedViewOf(const CalibratedView& view, const DistantOptions& options) {
  ReducedView g;
  g.factor = std::max(1, (std::max(view.width, view.height) + options.max_side - 1) / options.max_side);
  g.factor = std::min(g.factor, std::max(1, std::min(view.width, view.height)));
  const CalibratedView reduced = ReduceView(view, g.factor);
  g.rgb = reduced.image;
  g.valid = reduced.valid.empty() ? cv::Mat(reduced.image.size(), CV_8UC1, cv::Scalar(255))
                                  : reduced.valid.clone();
  g.K = reduced.K;
  g.R = reduced.cam_from_world.rotation.toRotationMatrix();
  g.centre = reduced.centre;
  g.P = reduced.P;
  g.texture = std::max(options.min_texture, options.texture_noise_factor * ImageNoiseSigma(Grey(g)));
  return g;
}

bool Sample(const ReducedView& g, const Eigen::Vector2d& colmap, float* value) {
  const Eigen::Vector2d cv = OpenCvFromColmap(colmap);
  const int x0 = static_cast<int>(std::floor(cv.x())), y0 = static_cast<int>(std::floor(cv.y()));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= g.rgb.cols || y0 + 1 >= g.rgb.rows) return false;
  if (!g.valid.at<uint8_t>(y0, x0) || !g.valid.at<uint8_t>(y0 + 1, x0 + 1)) return false;
  const float fx = static_cast<float>(cv.x() - x0), fy = static_cast<float>(cv.y() - y0);
  const cv::Vec3b* a = g.rgb.ptr<cv::Vec3b>(y0);
  const cv::Vec3b* b = g.rgb.ptr<cv::Vec3b>(y0 + 1);
  for (int c = 0; c < 3; ++c) {
    value[c] = (1 - fy) * ((1 - fx) * a[x0][c] + fx * a[x0 + 1][c]) +
               fy * ((1 - fx) * b[x0][c] + fx * b[x0 + 1][c]);
  }
  return true;
}

bool Mean3x3(const ReducedView& g, const Eigen::Vector2d& p, float* mean) {
  float value[3];
  mean[0] = mean[1] = mean[2] = 0.0f;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      if (!Sample(g, p + Eigen::Vector2d(dx, dy), value)) return false;
      for (int c = 0; c < 3; ++c) mean[c] += value[c] / 9.0f;
    }
  }
  return true;
}

}  // namespace raycarve
