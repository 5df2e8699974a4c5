#include "export/background_check.h"

#include <cmath>
#include <sstream>

namespace raycarve {
namespace exporter {

std::string BackgroundCheck::Summary() const {
  std::ostringstream text;
  text.precision(3);
  text << on_background << " of " << num_points << " points (" << 100.0 * share
       << "%) project onto background in most of the masked views that see them";
  return text.str();
}

BackgroundCheck CheckBackground(const std::vector<Eigen::Vector3f>& points,
                                const std::vector<CalibratedView>& views) {
  BackgroundCheck check;
  for (const Eigen::Vector3f& point : points) {
    const Eigen::Vector3d world = point.cast<double>();
    int seen = 0, background = 0;
    for (const CalibratedView& view : views) {
      if (view.mask.empty() || view.Depth(world) <= 0.0) continue;
      const Eigen::Vector2d pixel = view.Project(world);
      const int col = static_cast<int>(std::floor(pixel.x()));
      const int row = static_cast<int>(std::floor(pixel.y()));
      if (col < 0 || row < 0 || col >= view.width || row >= view.height) continue;
      if (view.valid.at<uint8_t>(row, col) == 0) continue;
      ++seen;
      background += view.mask.at<uint8_t>(row, col) == 0;
    }
    if (seen == 0) continue;
    ++check.num_points;
    check.on_background += 2 * background > seen;
  }
  check.share = check.num_points == 0 ? 0.0 : static_cast<double>(check.on_background) / check.num_points;
  return check;
}

}  // namespace exporter
}  // namespace raycarve
