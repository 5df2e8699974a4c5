#include "export/point_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace raycarve {
namespace exporter {

Rendering RenderPoints(const std::vector<ColouredPoint>& points,
                       const CalibratedView& view,
                       double point_size) {
  Rendering rendering;
  rendering.image = cv::Mat(view.height, view.width, CV_8UC3, cv::Scalar::all(0));
  rendering.silhouette = cv::Mat(view.height, view.width, CV_8UC1, cv::Scalar(0));
  rendering.depth = cv::Mat(view.height, view.width, CV_32FC1,
                            cv::Scalar(std::numeric_limits<float>::infinity()));
  const double focal = 0.5 * (view.K(0, 0) + view.K(1, 1));
  for (const ColouredPoint& point : points) {
    const Eigen::Vector3d world = point.xyz.cast<double>();
    const double depth = view.Depth(world);
    if (!(depth > 0.0)) continue;
    const Eigen::Vector2d pixel = view.Project(world);
    const double radius = 0.5 * point_size * focal / depth;
    // Pixel centres (c + 0.5) within [x - radius, x + radius], at least the pixel holding x.
    int col_min = static_cast<int>(std::ceil(pixel.x() - radius - 0.5));
    int col_max = static_cast<int>(std::floor(pixel.x() + radius - 0.5));
    int row_min = static_cast<int>(std::ceil(pixel.y() - radius - 0.5));
    int row_max = static_cast<int>(std::floor(pixel.y() + radius - 0.5));
    if (col_min > col_max) col_min = col_max = static_cast<int>(std::floor(pixel.x()));
    if (row_min > row_max) row_min = row_max = static_cast<int>(std::floor(pixel.y()));
    col_min = std::max(col_min, 0);
    row_min = std::max(row_min, 0);
    col_max = std::min(col_max, view.width - 1);
    row_max = std::min(row_max, view.height - 1);
    const float z = static_cast<float>(depth);
    for (int row = row_min; row <= row_max; ++row) {
      float* depths = rendering.depth.ptr<float>(row);
      cv::Vec3b* colours = rendering.image.ptr<cv::Vec3b>(row);
      uint8_t* covered = rendering.silhouette.ptr<uint8_t>(row);
      for (int col = col_min; col <= col_max; ++col) {
        if (z >= depths[col]) continue;
        depths[col] = z;
        colours[col] = cv::Vec3b(point.rgb[0], point.rgb[1], point.rgb[2]);
        covered[col] = 255;
      }
    }
  }
  return rendering;
}

}  // namespace exporter
}  // namespace raycarve
