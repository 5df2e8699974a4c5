#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/calibrated_view.h"

namespace raycarve {
namespace exporter {

struct BackgroundCheck {
  size_t num_points = 0;         // points seen (in front, inside the frame) by a masked view
  size_t on_background = 0;      // of those, points on background in more than half of them
  double share = 0.0;            // on_background / num_points
  std::string Summary() const;
};

// How much of a reconstruction is background: each point is projected into every view with a
// mask where it lies in front of the camera and on a pixel with photo data; it counts as on
// background when the mask says background in more than half of those views. Occlusion is not
// modelled: a point hidden behind the object projects onto object pixels and is not counted.
BackgroundCheck CheckBackground(const std::vector<Eigen::Vector3f>& points,
                                const std::vector<CalibratedView>& views);

}  // namespace exporter
}  // namespace raycarve
