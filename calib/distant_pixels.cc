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
       << " pixels of plain regions bounded by them (" << rays.size() << " rays; " << grown_refused
       << " of theirs left out: the other photos see another colour there); " << nearer
       << " were found inside it; " << seconds << " s";
  return text.str();
}

double ImageNoiseSigma(const cv::Mat& grey) {
  CHECK_EQ(grey.type(), CV_32F);
  if (grey.rows < 3 || grey.cols < 3) return 0.0;
  const cv::Mat kernel = (cv::Mat_<float>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
  cv::Mat response;
  cv::filter2D(grey, response, CV_32F, kernel, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
  // Over blocks of 8 x 8 pixels, the mean absolute response. The plain blocks are those within
  // twice the tenth percentile (a block's noise varies by about a tenth; texture lies far above),
  // and their median is the noise's. Texture over up to four fifths of the photo (gravel or a
  // patterned floor filling it, a facade) leaves it as the plain parts' noise: the median of all
  // the responses read a photo 80% textured (cells of 3 pixels) as 4.7 levels of noise for 3.
  constexpr int kBlock = 8;
  std::vector<float> blocks;
  for (int row = 1; row + kBlock <= grey.rows - 1; row += kBlock) {
    for (int col = 1; col + kBlock <= grey.cols - 1; col += kBlock) {
      double sum = 0.0;
      for (int y = row; y < row + kBlock; ++y) {
        const float* line = response.ptr<float>(y);
        for (int x = col; x < col + kBlock; ++x) sum += std::abs(line[x]);
      }
      blocks.push_back(static_cast<float>(sum / (kBlock * kBlock)));
    }
  }
  if (blocks.size() >= 10) {
    std::sort(blocks.begin(), blocks.end());
    const float limit = 2.0f * blocks[blocks.size() / 10];
    const size_t plain = std::upper_bound(blocks.begin(), blocks.end(), limit) - blocks.begin();
    // For Gaussian noise of sigma s the response is Gaussian of sigma 6 s (the kernel's squares
    // sum to 36); the median of its blocks' mean absolute values, so chosen, is 4.736 s
    // (simulated: 20 images of 512 x 512, spread 0.25%).
    return blocks[(plain - 1) / 2] / 4.736;
  }
  // Too small for blocks: the median absolute response (0.6745 of its sigma for a Gaussian).
  std::vector<float> values;
  values.reserve(static_cast<size_t>(grey.rows - 2) * (grey.cols - 2));
  for (int row = 1; row < grey.rows - 1; ++row) {
    const float* line = response.ptr<float>(row);
    for (int col = 1; col < grey.cols - 1; ++col) values.push_back(std::abs(line[col]));
  }
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
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
