#include "carve/known_surface.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "carve/carver.h"

namespace raycarve {

std::vector<cv::Mat> KnownSurfaceDepths(const std::vector<CalibratedView>& views,
                                        const VoxelGrid& grid,
                                        const std::vector<SurfacePoint>& points) {
  // Per view, the projections (x, y, depth) of the points it saw.
  std::vector<std::vector<Eigen::Vector3d>> seen(views.size());
  for (const SurfacePoint& point : points) {
    for (int v : point.views) {
      const Eigen::Vector3d pixel = views[v].P * point.xyz.homogeneous();
      if (pixel.z() > 0.0) seen[v].emplace_back(pixel.x() / pixel.z(), pixel.y() / pixel.z(), pixel.z());
    }
  }
  std::vector<cv::Mat> depths(views.size());
  std::vector<double> nearest;
  for (size_t v = 0; v < views.size(); ++v) {
    const CalibratedView& view = views[v];
    if (seen[v].empty()) continue;
    // The spacing of the known surface in this view: the median distance from an observation to
    // its nearest neighbour (exact; observations sorted by x, each searched outwards until the x
    // gap alone exceeds the nearest found).
    nearest.clear();
    std::vector<Eigen::Vector2d> sorted;
    sorted.reserve(seen[v].size());
    for (const Eigen::Vector3d& at : seen[v]) sorted.push_back(at.head<2>());
    std::sort(sorted.begin(), sorted.end(),
              [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() < b.x(); });
    for (size_t i = 0; i < sorted.size(); ++i) {
      double best = std::numeric_limits<double>::infinity();
      for (size_t j = i + 1; j < sorted.size(); ++j) {
        const double dx = sorted[j].x() - sorted[i].x();
        if (dx * dx >= best) break;
        best = std::min(best, (sorted[j] - sorted[i]).squaredNorm());
      }
      for (size_t j = i; j-- > 0;) {
        const double dx = sorted[i].x() - sorted[j].x();
        if (dx * dx >= best) break;
        best = std::min(best, (sorted[j] - sorted[i]).squaredNorm());
      }
      if (std::isfinite(best)) nearest.push_back(std::sqrt(best));
    }
    double spacing = 0.0;
    if (!nearest.empty()) {
      std::nth_element(nearest.begin(), nearest.begin() + nearest.size() / 2, nearest.end());
      spacing = nearest[nearest.size() / 2];
    }
    depths[v] = cv::Mat::zeros(view.height, view.width, CV_32F);
    const double focal = 0.5 * (view.K(0, 0) + view.K(1, 1));
    for (const Eigen::Vector3d& at : seen[v]) {
      const double x = at.x(), y = at.y();
      const double radius = std::max(kKnownSurfaceRadiusVoxels * focal * grid.voxel_size() / at.z(),
                                     kKnownSurfaceRadiusSpacings * spacing);
      const int r = static_cast<int>(std::ceil(radius));
      const int r0 = static_cast<int>(std::floor(y));
      const float depth = static_cast<float>(at.z());
      for (int row = std::max(0, r0 - r); row <= std::min(view.height - 1, r0 + r); ++row) {
        // The row's pixels whose centres lie within the radius: |col + 0.5 - x| <= half.
        const double dy = row + 0.5 - y;
        const double half_squared = radius * radius - dy * dy;
        if (half_squared < 0.0) continue;
        const double half = std::sqrt(half_squared);
        const int first = std::max(0, static_cast<int>(std::ceil(x - half - 0.5)));
        const int last = std::min(view.width - 1, static_cast<int>(std::floor(x + half - 0.5)));
        float* line = depths[v].ptr<float>(row);
        for (int col = first; col <= last; ++col) line[col] = std::max(line[col], depth);
      }
    }
  }
  return depths;
}

}  // namespace raycarve
