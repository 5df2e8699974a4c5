#pragma once

#include <Eigen/Core>

namespace raycarve {

// The one place where the two pixel conventions meet.
//
// COLMAP (and every raycarve model, camera and projection matrix) puts the top-left corner of the
// image at (0, 0) and the centre of the top-left pixel at (0.5, 0.5). OpenCV indexes pixel
// centres at integers: cv::Mat element (row r, col c) has its centre at (c, r), which is COLMAP's
// (c + 0.5, r + 0.5). Use these two functions whenever a coordinate crosses into cv::remap,
// cv::Mat indexing or back.
constexpr double kColmapPixelCentreOffset = 0.5;

inline Eigen::Vector2d ColmapFromOpenCv(const Eigen::Vector2d& opencv_xy) {
  return opencv_xy.array() + kColmapPixelCentreOffset;
}

inline Eigen::Vector2d OpenCvFromColmap(const Eigen::Vector2d& colmap_xy) {
  return colmap_xy.array() - kColmapPixelCentreOffset;
}

// COLMAP coordinates of the centre of cv::Mat element (row, col).
inline Eigen::Vector2d PixelCentre(int row, int col) {
  return ColmapFromOpenCv(Eigen::Vector2d(col, row));
}

}  // namespace raycarve
