#pragma once
// Internal to calib/: the border band of a photo that background_mask.cc and object_mask.cc
// both read (the backdrop's colours are taken there; the frame is never object).

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace raycarve {

// The band of 2% of rows and columns inside the frame, as `border` (pixels, at most ~40,000
// by a regular stride) and as a test of whether a pixel lies in it.
struct BorderBand {
  int top, bottom, left, right;  // first row/col inside the band's inner edge, per side
  int frame[4];
  bool InFrame(int row, int col, int rows, int cols) const {
    return row < frame[0] || row >= rows - frame[1] || col < frame[2] || col >= cols - frame[3];
  }
  bool InBand(int row, int col, int rows, int cols) const {
    return !InFrame(row, col, rows, cols) &&
           (row < top || row >= rows - bottom || col < left || col >= cols - right);
  }
};

// The band of `rgb` inside `frame` (top, bottom, left, right widths in pixels).
BorderBand MakeBand(const cv::Mat& rgb, const int frame[4]);

inline Eigen::Vector3d ToVector(const cv::Vec3b& p) { return Eigen::Vector3d(p[0], p[1], p[2]); }

}  // namespace raycarve
