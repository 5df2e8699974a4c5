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
    // its nearest neighbour (brute force; a few thousand points a view at most).
    nearest.clear();
    for (size_t i = 0; i < seen[v].size(); ++i) {
      double best = std::numeric_limits<double>::infinity();
      for (size_t j = 0; j < seen[v].size(); ++j) {
        if (i != j) best = std::min(best, (seen[v][i].head<2>() - seen[v][j].head<2>()).squaredNorm());
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
      const int c0 = static_cast<int>(std::floor(x)), r0 = static_cast<int>(std::floor(y));
      for (int row = std::max(0, r0 - r); row <= std::min(view.height - 1, r0 + r); ++row) {
        float* line = depths[v].ptr<float>(row);
        for (int col = std::max(0, c0 - r); col <= std::min(view.width - 1, c0 + r); ++col) {
          const double dx = col + 0.5 - x, dy = row + 0.5 - y;
          if (dx * dx + dy * dy > radius * radius) continue;
          line[col] = std::max(line[col], static_cast<float>(at.z()));
        }
      }
    }
  }
  return depths;
}

}  // namespace raycarve
