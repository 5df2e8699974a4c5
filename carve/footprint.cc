#include "carve/footprint.h"

#include <algorithm>
#include <cmath>

namespace raycarve {
namespace {

constexpr double kSlackPx = 0.01;

// Two doubles at once (SSE2 on x86-64; GCC's and Clang's vector extension elsewhere too): a
// footprint's eight corners as four pairs.
typedef double Pair __attribute__((vector_size(16)));

// ceil(v) and floor(v) as ints, without the library's rounding calls (SSE2 has no rounding
// instruction). `v` is first clamped far beyond any photo, so that the conversion is exact and
// defined (a corner near the camera's plane projects to infinity); the clamps that follow give
// the same footprint.
constexpr double kFarPx = 1e9;
int CeilToInt(double v) {
  v = std::min(std::max(v, -kFarPx), kFarPx);
  const int truncated = static_cast<int>(v);  // towards zero
  return truncated + (v > truncated ? 1 : 0);
}
int FloorToInt(double v) {
  v = std::min(std::max(v, -kFarPx), kFarPx);
  const int truncated = static_cast<int>(v);
  return truncated - (v < truncated ? 1 : 0);
}

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
  // Corners (0, 1), (2, 3), (4, 5) and (6, 7) (bit 0: +x, bit 1: +y, bit 2: +z), each summed in
  // the order base + x + y + z, as one corner at a time would be.
  Pair h[3][4];
  for (int axis = 0; axis < 3; ++axis) {
    h[axis][0] = Pair{base[axis], base[axis] + ex[axis]};
    h[axis][1] = h[axis][0] + ey[axis];
    h[axis][2] = h[axis][0] + ez[axis];
    h[axis][3] = h[axis][1] + ez[axis];
  }
  for (int pair = 0; pair < 4; ++pair) {
    if (!(h[2][pair][0] > 0.0 && h[2][pair][1] > 0.0)) return Footprint();
  }
  double x[8], y[8];
  for (int pair = 0; pair < 4; ++pair) {
    const Pair inverse_depth = Pair{1.0, 1.0} / h[2][pair];
    const Pair px = h[0][pair] * inverse_depth, py = h[1][pair] * inverse_depth;
    x[2 * pair] = px[0];
    x[2 * pair + 1] = px[1];
    y[2 * pair] = py[0];
    y[2 * pair + 1] = py[1];
  }
  double x_min = INFINITY, x_max = -INFINITY, y_min = INFINITY, y_max = -INFINITY;
  for (int c = 0; c < 8; ++c) {
    x_min = std::min(x_min, x[c]);
    x_max = std::max(x_max, x[c]);
    y_min = std::min(y_min, y[c]);
    y_max = std::max(y_max, y[c]);
  }
  // Pixel centres c + 0.5 within [x_min, x_max], with kSlackPx to spare: rays are stepped in
  // floating point, so a ray grazing an edge may be in a voxel whose exact projection misses its
  // pixel centre by a hair; without slack such a ray would be missed and never stepped.
  if (x_max - 0.5 < 0 || y_max - 0.5 < 0 || x_min - 0.5 > width || y_min - 0.5 > height) {
    return Footprint();
  }
  Footprint footprint;
  footprint.col_min = std::max(0, CeilToInt(x_min - 0.5 - kSlackPx));
  footprint.col_max = std::min(width - 1, FloorToInt(x_max - 0.5 + kSlackPx));
  footprint.row_min = std::max(0, CeilToInt(y_min - 0.5 - kSlackPx));
  footprint.row_max = std::min(height - 1, FloorToInt(y_max - 0.5 + kSlackPx));
  return footprint;
}

}  // namespace raycarve
