#pragma once

#include <vector>

#include "calib/calibrated_view.h"
#include "carve/carver.h"
#include "carve/volume.h"
#include "export/point_renderer.h"

namespace raycarve {
namespace exporter {

// Draws a carved volume into one view's pinhole camera (K, cam_from_world, size; its pixels are
// not used) exactly as the carving saw it: through each pixel centre a ray is cast into the grid
// (RayImage's traversal) and the pixel takes the colour of the first solid voxel it reaches,
// which is always a surface voxel. Unlike splatting a cloud, the voxels' true cube outlines
// cover the image without gaps, and voxels no photo coloured still occlude.
//
// `surface` gives the surface voxels' colours (CarveResult::surface: index order). A pixel whose
// voxel has no colour (num_pixels 0: no photo saw it) is drawn, in the silhouette and at its
// depth, with the mean colour of the coloured surface voxels among its 26 neighbours (black if
// none), and counted in `uncoloured_pixels`. Depth is the voxel centre's depth along the
// optical axis. Cost: one ray traversal per pixel.
struct VolumeRendering : Rendering {
  int uncoloured_pixels = 0;
};
VolumeRendering RenderVolume(const Volume& volume,
                             const std::vector<ColouredVoxel>& surface,
                             const CalibratedView& view);

}  // namespace exporter
}  // namespace raycarve
