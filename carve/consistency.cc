#include "carve/consistency.h"

#include <cmath>

namespace raycarve {

std::string ConsistencyMethodToString(ConsistencyMethod method) {
  return method == ConsistencyMethod::kMeanColour ? "mean_colour" : "standard_deviation";
}

bool ConsistencyMethodFromString(const std::string& text, ConsistencyMethod* method) {
  for (ConsistencyMethod candidate :
       {ConsistencyMethod::kMeanColour, ConsistencyMethod::kStandardDeviation}) {
    if (text == ConsistencyMethodToString(candidate)) {
      *method = candidate;
      return true;
    }
  }
  return false;
}

ConsistencyTest::ConsistencyTest(ConsistencyMethod method, double threshold, int min_views)
    : method_(method), threshold_(threshold), min_views_(min_views) {}

Consistency ConsistencyTest::Evaluate(const std::vector<ViewColourStats>& views) const {
  Consistency result;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_squares = Eigen::Vector3d::Zero();
  for (const ViewColourStats& view : views) {
    if (view.count == 0) continue;
    ++result.num_views;
    result.num_pixels += view.count;
    sum += view.sum;
    sum_squares += view.sum_squares;
  }
  if (result.num_pixels == 0) return result;
  result.colour = sum / result.num_pixels;
  if (result.num_views < min_views_) return result;
  result.judged = true;
  if (method_ == ConsistencyMethod::kMeanColour) {
    double weighted = 0.0;
    for (const ViewColourStats& view : views) {
      if (view.count == 0) continue;
      weighted += view.count * (view.sum / view.count - result.colour).norm();
    }
    result.error = weighted / result.num_pixels;
  } else {
    const Eigen::Vector3d variance =
        (sum_squares / result.num_pixels - result.colour.cwiseProduct(result.colour))
            .cwiseMax(0.0);
    result.error = std::sqrt(variance.sum() / 3.0);
  }
  result.consistent = result.error <= threshold_;
  return result;
}

}  // namespace raycarve
