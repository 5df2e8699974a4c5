#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace raycarve {

// The part of the ray origin + t * direction (t >= 0) inside `box` (slab test): true, with the
// interval in [*t_near, *t_far], when the ray meets the box with t_near <= t_far; false otherwise.
bool ClipRayToBox(const Eigen::Vector3d& origin,
                  const Eigen::Vector3d& direction,
                  const Eigen::AlignedBox3d& box,
                  double* t_near,
                  double* t_far);

}  // namespace raycarve
