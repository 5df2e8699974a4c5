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
  // The corners as three arrays of 8, summed in the same order as one corner at a time would
  // be, so that the compiler can work on several at once.
  double hx[8], hy[8], hz[8];
  for (int c = 0; c < 8; ++c) {
    hx[c] = base.x();
    hy[c] = base.y();
    hz[c] = base.z();
    if (c & 1) hx[c] += ex.x(), hy[c] += ex.y(), hz[c] += ex.z();
    if (c & 2) hx[c] += ey.x(), hy[c] += ey.y(), hz[c] += ey.z();
    if (c & 4) hx[c] += ez.x(), hy[c] += ez.y(), hz[c] += ez.z();
  }
  bool in_front = true;
  for (int c = 0; c < 8; ++c) in_front &= hz[c] > 0.0;
  if (!in_front) return Footprint();
  double x_min = INFINITY, x_max = -INFINITY, y_min = INFINITY, y_max = -INFINITY;
  for (int c = 0; c < 8; ++c) {
    const double inverse_depth = 1.0 / hz[c];
    const double x = hx[c] * inverse_depth, y = hy[c] * inverse_depth;
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
