#include "export/holdout_score.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <glog/logging.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace raycarve {
namespace exporter {

cv::Mat SsimMap(const cv::Mat& a, const cv::Mat& b) {
  CHECK(a.type() == CV_8UC3 && b.type() == CV_8UC3 && a.size() == b.size());
  const double c1 = std::pow(0.01 * 255.0, 2.0), c2 = std::pow(0.03 * 255.0, 2.0);
  const auto blur = [](const cv::Mat& m) {
    cv::Mat out;
    cv::GaussianBlur(m, out, cv::Size(11, 11), 1.5, 1.5, cv::BORDER_REFLECT);
    return out;
  };
  std::vector<cv::Mat> xs, ys;
  cv::split(a, xs);
  cv::split(b, ys);
  cv::Mat sum(a.size(), CV_32FC1, cv::Scalar(0));
  for (int k = 0; k < 3; ++k) {
    cv::Mat x, y;
    xs[k].convertTo(x, CV_32FC1);
    ys[k].convertTo(y, CV_32FC1);
    const cv::Mat mx = blur(x), my = blur(y);
    const cv::Mat mx2 = mx.mul(mx), my2 = my.mul(my), mxy = mx.mul(my);
    const cv::Mat vx = blur(x.mul(x)) - mx2, vy = blur(y.mul(y)) - my2;
    const cv::Mat cxy = blur(x.mul(y)) - mxy;
    cv::Mat map;
    cv::divide((2.0 * mxy + c1).mul(2.0 * cxy + c2), (mx2 + my2 + c1).mul(vx + vy + c2), map);
    sum += map;
  }
  return sum / 3.0;
}

HoldoutScore ScoreRendering(const Rendering& rendering, const CalibratedView& view) {
  HoldoutScore score;
  cv::Mat region = view.valid.clone();
  if (!view.mask.empty()) region &= (rendering.silhouette | view.mask);
  double squared = 0.0;
  for (int row = 0; row < view.height; ++row) {
    const cv::Vec3b* photo = view.image.ptr<cv::Vec3b>(row);
    const cv::Vec3b* render = rendering.image.ptr<cv::Vec3b>(row);
    const uint8_t* in = region.ptr<uint8_t>(row);
    for (int col = 0; col < view.width; ++col) {
      if (!in[col]) continue;
      ++score.scored_pixels;
      for (int k = 0; k < 3; ++k) {
        const double d = static_cast<double>(photo[col][k]) - render[col][k];
        squared += d * d;
      }
    }
  }
  const double mse = score.scored_pixels == 0 ? 0.0 : squared / (3.0 * score.scored_pixels);
  score.psnr = mse == 0.0 ? std::numeric_limits<double>::infinity()
                          : 10.0 * std::log10(255.0 * 255.0 / mse);
  if (score.scored_pixels > 0) {
    score.ssim = cv::mean(SsimMap(view.image, rendering.image), region)[0];
  }
  if (!view.mask.empty()) {
    const cv::Mat object = view.mask & view.valid;
    const cv::Mat drawn = rendering.silhouette & view.valid;
    const int both = cv::countNonZero(object & drawn);
    const int either = cv::countNonZero(object | drawn);
    score.silhouette_iou = either == 0 ? 1.0 : static_cast<double>(both) / either;
  }
  return score;
}

double BlockMeanPsnr(const CalibratedView& view, int block) {
  block = std::max(block, 1);
  const cv::Mat region = view.mask.empty() ? view.valid : (view.valid & view.mask);
  double squared = 0.0;
  int64_t scored = 0;
  for (int top = 0; top < view.height; top += block) {
    for (int left = 0; left < view.width; left += block) {
      const cv::Rect cell(left, top, std::min(block, view.width - left),
                          std::min(block, view.height - top));
      const cv::Scalar mean = cv::mean(view.image(cell));
      for (int row = cell.y; row < cell.y + cell.height; ++row) {
        const cv::Vec3b* photo = view.image.ptr<cv::Vec3b>(row);
        const uint8_t* in = region.ptr<uint8_t>(row);
        for (int col = cell.x; col < cell.x + cell.width; ++col) {
          if (!in[col]) continue;
          ++scored;
          for (int k = 0; k < 3; ++k) {
            const double d = photo[col][k] - mean[k];
            squared += d * d;
          }
        }
      }
    }
  }
  const double mse = scored == 0 ? 0.0 : squared / (3.0 * scored);
  return mse == 0.0 ? std::numeric_limits<double>::infinity()
                    : 10.0 * std::log10(255.0 * 255.0 / mse);
}

cv::Mat SideBySide(const Rendering& rendering, const CalibratedView& view) {
  cv::Mat error;
  cv::absdiff(view.image, rendering.image, error);
  error.convertTo(error, CV_8UC3, 4.0);
  cv::Mat strip;
  cv::hconcat(std::vector<cv::Mat>{view.image, rendering.image, error}, strip);
  return strip;
}

const char* SparseDepthVerdictName(SparseDepthVerdict verdict) {
  switch (verdict) {
    case SparseDepthVerdict::kAtDepth: return "at_depth";
    case SparseDepthVerdict::kHidden: return "hidden";
    case SparseDepthVerdict::kBehind: return "behind";
    case SparseDepthVerdict::kUndrawn: return "undrawn";
  }
  return "undrawn";
}

SparseDepthAgreement MeasureSparseDepth(const Rendering& rendering, const CalibratedView& view,
                                        const std::vector<Eigen::Vector3d>& points,
                                        double tolerance,
                                        std::vector<SparsePointDepth>* records) {
  CHECK_EQ(rendering.depth.type(), CV_32FC1);
  SparseDepthAgreement agreement;
  for (const Eigen::Vector3d& point : points) {
    const double depth = view.Depth(point);
    if (!(depth > 0.0)) continue;
    const Eigen::Vector2d pixel = view.Project(point);
    const int col = static_cast<int>(std::floor(pixel.x())), row = static_cast<int>(std::floor(pixel.y()));
    if (col < 0 || row < 0 || col >= rendering.depth.cols || row >= rendering.depth.rows) continue;
    ++agreement.points;
    const float drawn = rendering.depth.at<float>(row, col);
    SparseDepthVerdict verdict = SparseDepthVerdict::kUndrawn;
    if (!std::isfinite(drawn)) {
      verdict = SparseDepthVerdict::kUndrawn;
    } else if (std::abs(drawn - depth) <= tolerance) {
      ++agreement.at_depth;
      verdict = SparseDepthVerdict::kAtDepth;
    } else if (drawn < depth - tolerance) {
      ++agreement.hidden;
      verdict = SparseDepthVerdict::kHidden;
    } else {
      ++agreement.behind;
      verdict = SparseDepthVerdict::kBehind;
    }
    if (records != nullptr) records->push_back({point, depth, static_cast<double>(drawn), verdict});
  }
  return agreement;
}

}  // namespace exporter
}  // namespace raycarve
