#include "calib/distant_pixels.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <glog/logging.h>
#include <opencv2/imgproc.hpp>

namespace raycarve {

bool DistantOptions::IsValid(std::string* reason) const {
  if (max_side < 32) {
    *reason = "distant pixels: max_side must be at least 32";
  } else if (patch_radius < 1 || patch_radius > 8) {
    *reason = "distant pixels: patch_radius must be 1 to 8";
  } else if (stride < 1) {
    *reason = "distant pixels: stride must be at least 1";
  } else if (!(min_parallax > 0.0)) {
    *reason = "distant pixels: min_parallax must be positive";
  } else if (!(min_correlation > 0.0 && min_correlation <= 1.0)) {
    *reason = "distant pixels: min_correlation must be in (0, 1]";
  } else if (!(min_advantage >= 0.0)) {
    *reason = "distant pixels: min_advantage must be at least 0";
  } else if (min_agreeing_views < 1 || max_partners < min_agreeing_views) {
    *reason = "distant pixels: need 1 <= min_agreeing_views <= max_partners";
  } else {
    return true;
  }
  return false;
}

std::string DistantPixels::Summary() const {
  std::ostringstream text;
  text.precision(3);
  text << "distant pixels: " << distant << " of " << textured << " textured pixels judged in "
       << masks.size() << " photos show something beyond the volume, and " << grown
       << " pixels of plain regions bounded by them (" << rays.size() << " rays); " << nearer
       << " were found inside it; " << seconds << " s";
  return text.str();
}

double ImageNoiseSigma(const cv::Mat& grey) {
  CHECK_EQ(grey.type(), CV_32F);
  if (grey.rows < 3 || grey.cols < 3) return 0.0;
  const cv::Mat kernel = (cv::Mat_<float>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
  cv::Mat response;
  cv::filter2D(grey, response, CV_32F, kernel, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
  // The median absolute response, not the mean: texture over less than half of the photo (a
  // field, a facade) leaves it as the plain parts' noise.
  std::vector<float> values;
  values.reserve(static_cast<size_t>(grey.rows - 2) * (grey.cols - 2));
  for (int row = 1; row < grey.rows - 1; ++row) {
    const float* line = response.ptr<float>(row);
    for (int col = 1; col < grey.cols - 1; ++col) values.push_back(std::abs(line[col]));
  }
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  // For Gaussian noise of sigma s the response is Gaussian of sigma 6 s (the kernel's squares
  // sum to 36), and its median absolute value 0.6745 times that.
  return values[values.size() / 2] / (0.6745 * 6.0);
}

DistantPixels FindDistantPixels(const std::vector<CalibratedView>& views,
                                const Eigen::AlignedBox3d& box,
                                const DistantOptions& options,
                                const std::vector<std::vector<Eigen::Vector2d>>& observations) {
  const SupposedSurface sky = [](const Eigen::Vector3d&, const Eigen::Vector3d&, double* at,
                                 double* clear_to) {
    *at = std::numeric_limits<double>::infinity();
    *clear_to = std::numeric_limits<double>::infinity();
    return true;
  };
  return FindPixelsOnSurface(views, box, options, sky, observations);
}

}  // namespace raycarve
