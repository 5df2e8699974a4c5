#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "calib/calibrated_view.h"
#include "export/point_cloud_io.h"

namespace raycarve {
namespace exporter {

// A point cloud drawn into one view.
struct Rendering {
  cv::Mat image;       // CV_8UC3 RGB; black where nothing was drawn
  cv::Mat silhouette;  // CV_8UC1, 255 where some point was drawn
  cv::Mat depth;       // CV_32FC1, depth along the optical axis; +inf where nothing was drawn
};

// Draws `points` into `view`'s pinhole camera (K, cam_from_world, size; its pixels are not used)
// as square splats with a depth buffer: each point covers the pixels within the projection of a
// cube of side `point_size` (world units) centred on it, at least its own pixel. For a carved
// cloud, point_size is the voxel size. Cost: the splats' total area.
Rendering RenderPoints(const std::vector<ColouredPoint>& points,
                       const CalibratedView& view,
                       double point_size);

}  // namespace exporter
}  // namespace raycarve
