#include "carve/ground_pixels.h"

#include <sstream>

#include <glog/logging.h>

namespace raycarve {

DistantPixels FindGroundPixels(const std::vector<CalibratedView>& views,
                               const Eigen::AlignedBox3d& box,
                               const Ground& ground,
                               double clearance,
                               DistantOptions options,
                               const std::vector<std::vector<Eigen::Vector2d>>& observations) {
  CHECK(!ground.empty());
  CHECK(clearance >= 0.0);
  const GroundMap map(ground);
  const SupposedSurface plane = [&](const Eigen::Vector3d& centre, const Eigen::Vector3d& direction,
                                    double* at, double* clear_to) {
    const double height = ground.Height(centre);
    const double descent = -ground.normal.dot(direction);  // height lost per unit along the ray
    if (!(height > clearance) || !(descent > 1e-6)) return false;
    *at = height / descent;
    if (map.At(centre + *at * direction) != GroundMap::Foot::kGround) return false;
    *clear_to = (height - clearance) / descent;
    return true;
  };
  options.textured_quadrants = true;
  options.cell_rays = true;
  return FindPixelsOnSurface(views, box, options, plane, observations);
}

std::string GroundPixelsSummary(const DistantPixels& found) {
  std::ostringstream text;
  text.precision(3);
  text << "ground pixels: " << found.distant << " of " << found.textured << " textured pixels judged in "
       << found.photos_judged << " photos move as the ground's plane does (" << found.rays.size()
       << " rays); " << found.nearer << " were found above it; " << found.seconds << " s";
  return text.str();
}

}  // namespace raycarve
