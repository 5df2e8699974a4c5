#include "carve/footprint.h"

#include <cmath>

namespace raycarve {
namespace {

constexpr double kSlackPx = 0.01;

}  // namespace

Footprint ComputeFootprint(const Eigen::Matrix<double, 3, 4>& P,
                           int width,
                           int height,
                           const VoxelGrid& grid,
                           const Eigen::Vector3i& voxel,
                           int span) {
  // P * corner is affine in the corner, so project the first corner and add the columns.
  const Eigen::Vector3d base = P * grid.Corner(voxel, 0).homogeneous();
  const double s = grid.voxel_size() * span;
  const Eigen::Vector3d ex = s * P.col(0), ey = s * P.col(1), ez = s * P.col(2);
  double x_min = INFINITY, x_max = -INFINITY, y_min = INFINITY, y_max = -INFINITY;
  for (int c = 0; c < 8; ++c) {
    Eigen::Vector3d h = base;
    if (c & 1) h += ex;
    if (c & 2) h += ey;
    if (c & 4) h += ez;
    if (!(h.z() > 0.0)) return Footprint();
    const double inverse_depth = 1.0 / h.z();
    const double x = h.x() * inverse_depth, y = h.y() * inverse_depth;
    x_min = std::min(x_min, x);
    x_max = std::max(x_max, x);
    y_min = std::min(y_min, y);
    y_max = std::max(y_max, y);
  }
  // Pixel centres c + 0.5 within [x_min, x_max], with kSlackPx to spare: rays are stepped in
  // floating point, so a ray grazing an edge may be in a voxel whose exact projection misses its
  // pixel centre by a hair; without slack such a ray would be missed and never stepped.
  Footprint footprint;
  footprint.col_min = std::max(0, static_cast<int>(std::ceil(x_min - 0.5 - kSlackPx)));
  footprint.col_max = std::min(width - 1, static_cast<int>(std::floor(x_max - 0.5 + kSlackPx)));
  footprint.row_min = std::max(0, static_cast<int>(std::ceil(y_min - 0.5 - kSlackPx)));
  footprint.row_max = std::min(height - 1, static_cast<int>(std::floor(y_max - 0.5 + kSlackPx)));
  if (x_max - 0.5 < 0 || y_max - 0.5 < 0 || x_min - 0.5 > width || y_min - 0.5 > height) {
    return Footprint();
  }
  return footprint;
}

}  // namespace raycarve
