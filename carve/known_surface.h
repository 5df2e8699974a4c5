#pragma once
// Internal to carve/: the known surface's depth per view (CarveOptions::protect_surface_points).

#include <vector>

#include <opencv2/core.hpp>

#include "calib/calibrated_view.h"
#include "carve/surface_evidence.h"
#include "carve/voxel_grid.h"

namespace raycarve {

// Per view, the depth of the known surface near each pixel: around each surface point's
// projection, within kKnownSurfaceRadiusVoxels of its projected voxel width or
// kKnownSurfaceRadiusSpacings of the view's observation spacing, whichever is wider, the farthest
// depth of the points there (0: no point near). Empty for views no point names. Every point
// counts, inside the grid or not: the carve's points are those of its volume, and a tile of the
// volume (carve/tiling.h) is protected by the points beyond its edge as the whole grid is.
std::vector<cv::Mat> KnownSurfaceDepths(const std::vector<CalibratedView>& views,
                                        const VoxelGrid& grid,
                                        const std::vector<SurfacePoint>& points);

}  // namespace raycarve
