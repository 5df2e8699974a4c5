#include "calib/ray_box.h"

#include <algorithm>
#include <limits>
#include <utility>

namespace raycarve {

bool ClipRayToBox(const Eigen::Vector3d& origin,
                  const Eigen::Vector3d& direction,
                  const Eigen::AlignedBox3d& box,
                  double* t_near,
                  double* t_far) {
  *t_near = 0.0;
  *t_far = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    if (direction[axis] == 0.0) {
      if (origin[axis] < box.min()[axis] || origin[axis] > box.max()[axis]) return false;
      continue;
    }
    double t0 = (box.min()[axis] - origin[axis]) / direction[axis];
    double t1 = (box.max()[axis] - origin[axis]) / direction[axis];
    if (t0 > t1) std::swap(t0, t1);
    *t_near = std::max(*t_near, t0);
    *t_far = std::min(*t_far, t1);
    if (*t_near > *t_far) return false;
  }
  return true;
}

}  // namespace raycarve
