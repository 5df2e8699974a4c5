// Plain regions judged by their rims, for FindPixelsOnSurface (calib/surface_pixels.cc).
#include "calib/plain_regions.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "calib/pixel.h"

namespace raycarve {
namespace {

// A plain region is distant when at least this many of the judged pixels on its rim, and this
// share of them, are distant, and those found nearer are at most this share of the distant.
constexpr int kMinRimVotes = 3;
constexpr double kMinRimShare = 0.25;
constexpr double kMaxRimNearShare = 0.05;

}  // namespace

std::vector<Eigen::Vector2d> GrowIntoPlainRegions(const cv::Mat& grey, const cv::Mat& valid,
                                                  double texture, int factor,
                                                  const DistantOptions& options,
                                                  const std::vector<Eigen::Vector2d>& seen,
                                                  cv::Mat* mask, int64_t* grown) {
  const int side = 2 * options.patch_radius + 1;
  cv::Mat mean, square;
  cv::boxFilter(grey, mean, CV_32F, cv::Size(side, side));
  cv::boxFilter(grey.mul(grey), square, CV_32F, cv::Size(side, side));
  cv::Mat plain(grey.size(), CV_8UC1, cv::Scalar(0));
  const float limit = static_cast<float>(texture * texture);
  for (int row = options.patch_radius; row < grey.rows - options.patch_radius; ++row) {
    for (int col = options.patch_radius; col < grey.cols - options.patch_radius; ++col) {
      const float m = mean.at<float>(row, col);
      if (square.at<float>(row, col) - m * m < limit && valid.at<uint8_t>(row, col)) {
        plain.at<uint8_t>(row, col) = 255;
      }
    }
  }
  cv::Mat labels;
  const int count = cv::connectedComponents(plain, labels, 4, CV_32S);
  // Per region, the verdicts of the judged pixels within reach of it (a patch and a stride).
  std::vector<int> distant(count, 0), judged(count, 0), nearer(count, 0), size(count, 0);
  for (int row = 0; row < labels.rows; ++row) {
    for (int col = 0; col < labels.cols; ++col) ++size[labels.at<int>(row, col)];
  }
  const int reach = options.patch_radius + options.stride;
  std::vector<int> near_labels;
  for (int row = 0; row < mask->rows; ++row) {
    for (int col = 0; col < mask->cols; ++col) {
      const uint8_t verdict = mask->at<uint8_t>(row, col);
      if (verdict == 0) continue;
      near_labels.clear();
      for (int y = std::max(0, row - reach); y <= std::min(labels.rows - 1, row + reach); ++y) {
        for (int x = std::max(0, col - reach); x <= std::min(labels.cols - 1, col + reach); ++x) {
          const int label = labels.at<int>(y, x);
          if (label > 0 && std::find(near_labels.begin(), near_labels.end(), label) == near_labels.end()) {
            near_labels.push_back(label);
          }
        }
      }
      for (int label : near_labels) {
        ++judged[label];
        if (verdict == kDistantJudged) ++distant[label];
        if (verdict == kNearer) ++nearer[label];
      }
    }
  }
  std::vector<uint8_t> holds_point(count, 0);
  for (const Eigen::Vector2d& pixel : seen) {
    const Eigen::Vector2d at = OpenCvFromColmap(pixel / factor);
    const int col = static_cast<int>(std::lround(at.x())), row = static_cast<int>(std::lround(at.y()));
    if (col >= 0 && row >= 0 && col < labels.cols && row < labels.rows) holds_point[labels.at<int>(row, col)] = 1;
  }
  std::vector<uint8_t> is_distant(count, 0);
  for (int label = 1; label < count; ++label) {
    is_distant[label] = !holds_point[label] && size[label] >= side * side && distant[label] >= kMinRimVotes &&
                        distant[label] >= kMinRimShare * judged[label] &&
                        nearer[label] <= kMaxRimNearShare * distant[label];
  }
  std::vector<Eigen::Vector2d> pixels;
  for (int row = 0; row < labels.rows; ++row) {
    for (int col = 0; col < labels.cols; ++col) {
      if (!is_distant[labels.at<int>(row, col)]) continue;
      ++*grown;
      if (mask->at<uint8_t>(row, col) == 0) mask->at<uint8_t>(row, col) = kGrown;
      if (row % options.stride == 0 && col % options.stride == 0) pixels.push_back(PixelCentre(row, col));
    }
  }
  return pixels;
}

}  // namespace raycarve
