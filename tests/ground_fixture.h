#pragma once
// A supporting plane's ground as the sparse points would show it, for the tests of the carve's
// held ground and the mesh's levelling.

#include <cmath>

#include <Eigen/Core>

#include "carve/ground.h"

namespace raycarve {
namespace testing {

// Points every `spacing` over the square [-half, half]^2 of the plane through the origin across
// the world axis `axis` (0 x, 1 y, 2 z), the normal along that axis; reaching `radius`, its
// depth `depth`; with `outline`, the square's corners as its hull (in order around it).
inline Ground GridGround(int axis, double half, double spacing, double depth, double radius,
                         bool outline) {
  Ground ground;
  ground.normal = Eigen::Vector3d::Unit(axis);
  ground.offset = 0.0;
  ground.depth = depth;
  ground.radius = radius;
  const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
  const auto at = [u, v](double a, double b) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    p[u] = a;
    p[v] = b;
    return p;
  };
  const int steps = static_cast<int>(std::lround(half / spacing));
  for (int i = -steps; i <= steps; ++i) {
    for (int j = -steps; j <= steps; ++j) ground.footprint.push_back(at(spacing * i, spacing * j));
  }
  if (outline) ground.outline = {at(-half, -half), at(half, -half), at(half, half), at(-half, half)};
  return ground;
}

}  // namespace testing
}  // namespace raycarve
