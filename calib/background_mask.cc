#include "calib/background_mask.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include <glog/logging.h>
#include <opencv2/imgproc.hpp>

#include "calib/input_error.h"

namespace raycarve {

bool BackgroundOptions::IsValid(std::string* reason) const {
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) {
    *reason = "background tolerance must be a positive number";
    return false;
  }
  if (mode == Mode::kColour && !((colour.array() >= 0).all() && (colour.array() <= 255).all())) {
    *reason = "background colour must be three numbers in [0, 255]";
    return false;
  }
  return true;
}

BackgroundOptions::Mode ParseBackground(const std::string& text, Eigen::Vector3d* colour) {
  if (text == "none") return BackgroundOptions::Mode::kNone;
  if (text == "auto") return BackgroundOptions::Mode::kAuto;
  std::vector<double> values;
  bool numbers = true;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    char* end = nullptr;
    values.push_back(std::strtod(item.c_str(), &end));
    numbers = numbers && !item.empty() && end == item.c_str() + item.size();
  }
  if (!numbers || values.size() != 3) {
    throw InputError("--background_colour '" + text + "' is not none, auto or R,G,B (e.g. 0,0,0)");
  }
  *colour = Eigen::Vector3d(values[0], values[1], values[2]);
  return BackgroundOptions::Mode::kColour;
}

bool EstimateBackdropColour(const cv::Mat& rgb, double tolerance, Eigen::Vector3d* colour) {
  CHECK_EQ(rgb.type(), CV_8UC3);
  const int band_rows = std::max(1, rgb.rows / 50), band_cols = std::max(1, rgb.cols / 50);
  std::vector<cv::Vec3b> border;
  for (int row = 0; row < rgb.rows; ++row) {
    const bool edge_row = row < band_rows || row >= rgb.rows - band_rows;
    for (int col = 0; col < rgb.cols; ++col) {
      if (edge_row || col < band_cols || col >= rgb.cols - band_cols) {
        border.push_back(rgb.at<cv::Vec3b>(row, col));
      }
    }
  }
  for (int k = 0; k < 3; ++k) {
    std::vector<int> channel(border.size());
    for (size_t i = 0; i < border.size(); ++i) channel[i] = border[i][k];
    std::nth_element(channel.begin(), channel.begin() + channel.size() / 2, channel.end());
    (*colour)[k] = channel[channel.size() / 2];
  }
  size_t close = 0;
  for (const cv::Vec3b& p : border) {
    close += (Eigen::Vector3d(p[0], p[1], p[2]) - *colour).norm() <= tolerance;
  }
  return close >= 0.8 * border.size();
}

cv::Mat ObjectMaskFromBackdrop(const cv::Mat& rgb, const Eigen::Vector3d& backdrop, double tolerance) {
  CHECK_EQ(rgb.type(), CV_8UC3);
  cv::Mat mask(rgb.size(), CV_8UC1);
  const double tolerance2 = tolerance * tolerance;
  for (int row = 0; row < rgb.rows; ++row) {
    const cv::Vec3b* pixels = rgb.ptr<cv::Vec3b>(row);
    uint8_t* out = mask.ptr<uint8_t>(row);
    for (int col = 0; col < rgb.cols; ++col) {
      double d2 = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double d = pixels[col][k] - backdrop[k];
        d2 += d * d;
      }
      out[col] = d2 > tolerance2 ? 255 : 0;
    }
  }
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN, cv::Mat::ones(3, 3, CV_8U));
  cv::morphologyEx(mask, mask, cv::MORPH_CLOSE, cv::Mat::ones(5, 5, CV_8U));
  return mask;
}

}  // namespace raycarve
