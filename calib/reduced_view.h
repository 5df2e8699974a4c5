#pragma once
// Internal to calib/: a photo as the distant and ground pixels' test judges it (reduced), and its
// colour samples (calib/surface_pixels.cc).

#include <opencv2/core.hpp>

#include <Eigen/Core>

#include "calib/calibrated_view.h"
#include "calib/distant_pixels.h"

namespace raycarve {

// A photo as judged: reduced, with its geometry in the reduced pixels. Eight bits a channel: a
// photo of 640 x 480 holds 1.2 MB here, 200 of them 240 MB.
struct ReducedView {
  cv::Mat rgb;    // CV_8UC3
  cv::Mat valid;  // CV_8UC1
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // camera from world
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 3, 4> P = Eigen::Matrix<double, 3, 4>::Zero();
  int factor = 1;
  double texture = 0.0;  // the smallest standard deviation of a textured patch
};

// The photo in grey levels (CV_32F).
cv::Mat Grey(const ReducedView& g);

// The view reduced to at most options.max_side pixels a side, with its texture threshold.
ReducedView ReducedViewOf(const CalibratedView& view, const DistantOptions& options);

// Bilinear RGB at a COLMAP pixel position into value[0..2]; false outside the valid pixels.
bool Sample(const ReducedView& g, const Eigen::Vector2d& colmap, float* value);

// The mean colour of the 3 x 3 pixels around a COLMAP pixel position; false where one is not valid.
bool Mean3x3(const ReducedView& g, const Eigen::Vector2d& p, float* mean);

}  // namespace raycarve
