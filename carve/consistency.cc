#include "carve/consistency.h"

#include <algorithm>
#include <cmath>

namespace raycarve {

std::string ConsistencyMethodToString(ConsistencyMethod method) {
  switch (method) {
    case ConsistencyMethod::kMeanColour:
      return "mean_colour";
    case ConsistencyMethod::kStandardDeviation:
      return "standard_deviation";
    case ConsistencyMethod::kPatchCorrelation:
      return "ncc";
  }
  return "unknown";
}

bool ConsistencyMethodFromString(const std::string& text, ConsistencyMethod* method) {
  for (ConsistencyMethod candidate :
       {ConsistencyMethod::kMeanColour, ConsistencyMethod::kStandardDeviation,
        ConsistencyMethod::kPatchCorrelation}) {
    if (text == ConsistencyMethodToString(candidate)) {
      *method = candidate;
      return true;
    }
  }
  return false;
}

double MeanColourDifference::Error(const std::vector<ViewColourStats>& views,
                                   const Eigen::Vector3d& mean,
                                   int num_pixels) const {
  double weighted = 0.0;
  int seen = 0;
  for (const ViewColourStats& view : views) {
    if (view.count == 0) continue;
    weighted += view.count * (view.sum / view.count - mean).norm();
    ++seen;
  }
  const double correction =
      correct_view_count_ && seen > 1 ? std::sqrt(seen / (seen - 1.0)) : 1.0;
  return correction * weighted / num_pixels;
}

double PooledStandardDeviation::Error(const std::vector<ViewColourStats>& views,
                                      const Eigen::Vector3d& mean,
                                      int num_pixels) const {
  Eigen::Vector3d sum_squares = Eigen::Vector3d::Zero();
  for (const ViewColourStats& view : views) sum_squares += view.sum_squares;
  const Eigen::Vector3d variance =
      (sum_squares / num_pixels - mean.cwiseProduct(mean)).cwiseMax(0.0);
  return std::sqrt(variance.sum() / 3.0);
}

std::unique_ptr<ConsistencyFunction> MakeConsistencyFunction(ConsistencyMethod method,
                                                             bool correct_view_count) {
  // kPatchCorrelation's colour part is the mean-colour test; its pattern part is in the carver.
  if (method == ConsistencyMethod::kStandardDeviation) {
    return std::make_unique<PooledStandardDeviation>();
  }
  return std::make_unique<MeanColourDifference>(correct_view_count);
}

ConsistencyTest::ConsistencyTest(ConsistencyMethod method,
                                 double threshold,
                                 int min_views,
                                 double adaptive,
                                 bool correct_view_count,
                                 double spread_floor)
    : function_(MakeConsistencyFunction(method, correct_view_count)),
      threshold_(threshold),
      min_views_(min_views),
      adaptive_(adaptive),
      spread_floor_(spread_floor) {}

double ConsistencyTest::WithinViewSpread(const std::vector<ViewColourStats>& views) {
  double weighted = 0.0;
  int pixels = 0;
  for (const ViewColourStats& view : views) {
    if (view.count == 0) continue;
    const Eigen::Vector3d mean = view.sum / view.count;
    const Eigen::Vector3d variance =
        (view.sum_squares / view.count - mean.cwiseProduct(mean)).cwiseMax(0.0);
    weighted += view.count * std::sqrt(variance.sum());
    pixels += view.count;
  }
  return pixels == 0 ? 0.0 : weighted / pixels;
}

Consistency ConsistencyTest::Evaluate(const std::vector<ViewColourStats>& views) const {
  Consistency result;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const ViewColourStats& view : views) {
    if (view.count == 0) continue;
    ++result.num_views;
    result.num_pixels += view.count;
    sum += view.sum;
  }
  if (result.num_pixels == 0) return result;
  result.colour = sum / result.num_pixels;
  if (result.num_views < min_views_) return result;
  result.judged = true;
  result.error = function_->Error(views, result.colour, result.num_pixels);
  result.threshold = threshold_;
  if (adaptive_ != 0.0 || spread_floor_ != 0.0) {
    const double spread = WithinViewSpread(views);
    result.threshold += adaptive_ * spread;
    result.threshold = std::max(result.threshold, spread_floor_ * spread);
  }
  result.consistent = result.error <= result.threshold;
  return result;
}

}  // namespace raycarve
