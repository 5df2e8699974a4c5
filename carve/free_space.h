#pragma once

#include <cstdint>
#include <vector>

#include "calib/calibrated_view.h"
#include "calib/distant_pixels.h"
#include "carve/ground.h"
#include "carve/surface_evidence.h"
#include "carve/volume.h"

namespace raycarve {

struct FreeSpaceStatistics {
  int64_t sight_lines = 0;  // (point, view) pairs whose sight line crosses the grid
  int64_t carved = 0;       // solid voxels carved
  int64_t through_ground = 0;  // sight lines not drawn: down through the held ground
  double seconds = 0.0;
};

// Empty space from the sparse points: a view that observed a surface point saw it across empty
// space, so every voxel that the segment from the view's centre to the point passes through is
// carved, up to where the segment comes within `margin_voxels` voxel widths of the surface at the
// point. The surface's side is taken to face the mean direction from the point to its views (on
// a ring of cameras around a plane, its normal): a line at a slant to it stops farther from the
// point (margin / sin(slant), at most 4 margins), since it passes close over the surface beside
// the point; a view behind that plane draws no line. A voxel holding any of the points is never
// carved. Only solid voxels are carved; `points`' views index `views`. The voxels are found on
// `num_threads` threads (< 1: one per hardware thread) and carved in index order: the result does
// not depend on the count. Cost: one step per voxel a sight line passes (Amanatides-Woo).
// With a `ground` (CarveOptions::ground): a line that passes down through the ground's plane
// where the plane is ground (GroundMap::Foot::kGround) is not drawn: its point lies under the
// floor the carve holds, where a photo above could not have seen it (a wrong match; a step down
// opens a hole in the ground, and a line through the hole is drawn).
FreeSpaceStatistics CarveFreeSpace(const std::vector<CalibratedView>& views,
                                   const std::vector<SurfacePoint>& points,
                                   double margin_voxels,
                                   Volume* volume,
                                   int num_threads = 1,
                                   const Ground& ground = Ground());

// Empty space from the distant pixels (calib/distant_pixels.h): a photo pixel that shows
// something beyond the volume saw across all of it, so every solid voxel its ray passes through is
// carved. Where the known surface (KnownSurfaceDepths: sparse points that photo saw near the
// pixel) lies on the ray, the ray stops `margin_voxels` voxel widths in front of it: a window
// that mirrors the sky shows it at infinity, and the wall's points around it say where the window
// is. A voxel holding a surface point, and the voxels in `keep` (the held ground), are never
// carved. `rays`' views index `views`. Same threads and order as CarveFreeSpace. `known_depth`:
// KnownSurfaceDepths of the views, grid and points when already made (null: made here).
// With a `ground`: a ray of unbounded length that passes down through the plane where it is
// ground is not drawn (as in CarveFreeSpace): the pixel would show the ground there, not
// something beyond the volume (a pixel at an object's edge, misjudged).
FreeSpaceStatistics CarveDistantRays(const std::vector<CalibratedView>& views,
                                     const std::vector<DistantRay>& rays,
                                     const std::vector<SurfacePoint>& points,
                                     double margin_voxels,
                                     const std::vector<int64_t>& keep,
                                     Volume* volume,
                                     int num_threads = 1,
                                     const std::vector<cv::Mat>* known_depth = nullptr,
                                     const Ground& ground = Ground());

// The voxels of `grid` that the segment from `from` to `to` passes through, in order (a voxel
// whose closed cube the segment only touches at an edge or corner may or may not be listed),
// clipped to the grid's box. Appended to `voxels` as linear indices.
void SegmentVoxels(const VoxelGrid& grid,
                   const Eigen::Vector3d& from,
                   const Eigen::Vector3d& to,
                   std::vector<int64_t>* voxels);

}  // namespace raycarve
