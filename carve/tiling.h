#pragma once
// A carve split into tiles that separate processes carve (issue 46), in three steps:
//
// 1. CarveCoarseLevels: every level of detail but the final one, over the whole volume, once.
// 2. CarveTile, once per tile (independently, in any order, on any machine): the final level over
//    the tile's region of the final grid, the tile's core grown by an overlap, starting from the
//    coarse volume refined there. What lies outside the region is known from the coarse volume:
//    a pixel whose ray meets it before reaching the region shows something in front of the tile,
//    and is left out of the tile's views (TileViews), so that no voxel of the tile is judged
//    against the colour of a surface that hides it.
// 3. FinishTiledCarve, once: the cores joined (JoinTileCores) are carved on at the final level
//    with the whole volume's visibility, until every surface voxel passes the test as the single
//    carve's would (at tile borders, and where the coarse volume hid more than the fine one
//    would); then what the single carve does after its final level (components, silhouettes,
//    colours). The result is what CarveVolume returns.
//
// The three steps carve with the same options and the same final threshold (estimated once, in
// step 1, over the whole volume); what the tiles leave differs from a single carve only where the
// order of carving or the coarse volume's view of the outside decided otherwise.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "calib/calibrated_view.h"
#include "carve/carver.h"
#include "carve/volume.h"

namespace raycarve {

// One tile of the final grid: the voxels it decides (its core; the cores partition the grid)
// and those it carves (the core grown by the overlap on every side, inside the grid). Voxel
// coordinates of the final grid, [lo, hi) per axis, even where not at the grid's end.
struct TileRegion {
  int index = 0;  // x fastest, then y, then z
  Eigen::Vector3i core_lo = Eigen::Vector3i::Zero();
  Eigen::Vector3i core_hi = Eigen::Vector3i::Zero();
  Eigen::Vector3i lo = Eigen::Vector3i::Zero();
  Eigen::Vector3i hi = Eigen::Vector3i::Zero();
  int64_t CoreVoxels() const {
    const Eigen::Vector3i n = core_hi - core_lo;
    return static_cast<int64_t>(n.x()) * n.y() * n.z();
  }
};

// Whether a carve with `options` over `box` can be split into `tiles` (per axis) with an overlap
// of `overlap` final voxels: at least two levels of detail (the tiles start from the coarser
// ones), an even overlap of at least 2, and cores of at least 4 voxels along each axis. False,
// with the reason, otherwise.
bool CheckTiling(const Eigen::AlignedBox3d& box,
                 const CarveOptions& options,
                 const Eigen::Vector3i& tiles,
                 int overlap,
                 std::string* reason);

// The tiles of a grid of `dimensions` voxels cut `tiles` times along each axis (CheckTiling's
// rules hold): cores of about equal, even sizes.
std::vector<TileRegion> SplitIntoTiles(const Eigen::Vector3i& dimensions,
                                       const Eigen::Vector3i& tiles,
                                       int overlap);

// Whether any part of `box` may be in view: no side of the view's frustum (the four planes
// through the camera centre and the photo's edges, and the camera's own plane) has every corner of
// the box outside it. Conservative: a box near a frustum's edge may pass without being seen.
bool BoxInView(const CalibratedView& view, const Eigen::AlignedBox3d& box);

// Step 1's result.
struct CoarseCarve {
  explicit CoarseCarve(const VoxelGrid& grid) : volume(grid) {}
  Volume volume;  // the level before the final one
  // The final level's thresholds (RGB units; the pattern threshold with patch correlation).
  double final_threshold = 0.0;
  double final_pattern_threshold = 0.0;
  CarveStatistics statistics;  // of the coarse levels
};

// Step 1. Options must pass CheckCarveFits and CheckTiling (CHECKed).
CoarseCarve CarveCoarseLevels(const std::vector<CalibratedView>& views,
                              const Eigen::AlignedBox3d& box,
                              const CarveOptions& options,
                              const std::function<void(const CarveProgress&)>& progress = {},
                              double progress_interval_seconds = 1.0);

// The views as the voxels inside `tile_box` see them: a pixel whose ray meets a solid voxel of
// `outside` (a volume that holds nothing inside the tile) before it enters the box is made
// invalid; every other pixel keeps its validity. `occluded_pixels` (may be null) gets how many
// were made invalid. The photos themselves are shared, not copied. `num_threads` < 1: one per
// core.
std::vector<CalibratedView> TileViews(const std::vector<CalibratedView>& views,
                                      const Volume& outside,
                                      const Eigen::AlignedBox3d& tile_box,
                                      int num_threads,
                                      int64_t* occluded_pixels);

// Step 2's result: the tile's region after carving (its grid is the final grid's Region).
struct TileCarve {
  explicit TileCarve(const VoxelGrid& grid) : volume(grid) {}
  Volume volume;
  int64_t occluded_pixels = 0;  // TileViews' count
  CarveStatistics statistics;
};

// Step 2 for `tile`, from step 1's `coarse` (its volume and thresholds).
TileCarve CarveTile(const std::vector<CalibratedView>& views,
                    const Eigen::AlignedBox3d& box,
                    const CarveOptions& options,
                    const CoarseCarve& coarse,
                    const TileRegion& tile,
                    const std::function<void(const CarveProgress&)>& progress = {},
                    double progress_interval_seconds = 1.0);

// A tile's core: its solid bits, x fastest over core_lo .. core_hi, 64 to a word. `volume` is the
// tile's region (TileCarve::volume).
std::vector<uint64_t> CoreBits(const Volume& volume, const TileRegion& tile);

// Step 3's input: the final grid's volume from every tile's CoreBits (`cores[i]` for `tiles[i]`;
// an empty vector stands for a core with no solid voxel).
Volume JoinTileCores(const VoxelGrid& grid,
                     const std::vector<TileRegion>& tiles,
                     const std::vector<std::vector<uint64_t>>& cores);

// Step 3: what CarveVolume returns, from the joined cores and step 1's volume (`coarse`: what
// CarveOptions::lod_carve_depth holds).
CarveResult FinishTiledCarve(const std::vector<CalibratedView>& views,
                             const Eigen::AlignedBox3d& box,
                             const CarveOptions& options,
                             Volume joined,
                             const Volume& coarse,
                             double final_threshold,
                             double final_pattern_threshold,
                             const std::function<void(const CarveProgress&)>& progress = {},
                             double progress_interval_seconds = 1.0);

}  // namespace raycarve
