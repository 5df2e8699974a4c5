#pragma once
// Photo pixels that show the ground: free space over an unmasked capture's floor. Voxel colouring
// keeps what the photos agree on, and over a plain or repetitive floor, or where few photos see
// (between the objects and the clutter around them), they agree on much that is empty: the photo
// hull bulges up from the floor. A textured patch of a photo that moves between the photos as the
// ground plane does, and as no point on its ray in front of the plane would, shows the floor: the
// photo saw across empty space down to it.

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "calib/calibrated_view.h"
#include "calib/distant_pixels.h"
#include "carve/ground.h"

namespace raycarve {

// The test of FindPixelsOnSurface (calib/distant_pixels.h) with the ground's plane as the surface,
// where its foot is on the ground (GroundMap::At): a pixel's ray meets the plane and, if it shows
// the floor there, crossed empty space until it came within `clearance` of the plane, or until the
// photos that say so no longer tell its point from the plane's where that is higher (rays returned
// with that length; what lies nearer the plane is left to colour carving). The pipeline passes the
// ground's tolerance (Ground::depth): the band of the sparse points on the plane. Judged patches
// must be textured in each quadrant (DistantOptions::textured_quadrants, set here): the foot of a
// plain box on a textured floor moves with the floor in photos near each other (they share the
// box's occlusion of the floor behind it), and its plain half says nothing. A pixel found casts the
// rays of its stride cell (DistantOptions::cell_rays, set here). Plain regions are not grown from
// their rims unless `options.grow_plain_regions` (an object of the floor's colour merges with it).
// `ground` must not be empty; `observations` as for FindDistantPixels.
DistantPixels FindGroundPixels(const std::vector<CalibratedView>& views,
                               const Eigen::AlignedBox3d& box,
                               const Ground& ground,
                               double clearance,
                               DistantOptions options,
                               const std::vector<std::vector<Eigen::Vector2d>>& observations = {});

// One line for the log: FindGroundPixels' counts.
std::string GroundPixelsSummary(const DistantPixels& found);

}  // namespace raycarve
