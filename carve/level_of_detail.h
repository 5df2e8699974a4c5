#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "carve/surface_evidence.h"
#include "carve/volume.h"
#include "carve/voxel_grid.h"

namespace raycarve {

// Prock and Dyer's coarse-to-fine carving, as the seed paper applies it: carve at a coarse
// resolution, augment what survived by a band of voxels (so that over-eager coarse carving can be
// undone), split each voxel into 8 and carve again, up to the target resolution.

// One level's figures.
struct LevelStatistics {
  int resolution = 0;
  int image_factor = 1;  // the photos were reduced this many times (CarveOptions::lod_reduce_images)
  int image_enlargement = 1;  // or enlarged this many times (CarveOptions::supersample)
  double threshold = 0.0;  // the consistency threshold this level judged with
  double pattern_threshold = 0.0;  // and, with kPatchCorrelation, its pattern threshold
  // CarveOptions::auto_threshold: whether the threshold came from the surface points (false:
  // too few could be judged, and the fallback was used); `estimate` holds what it came from.
  bool threshold_from_data = false;
  // With enlarged photos: the grid `estimate` was measured at (the photos as they are, a grid as
  // many times coarser); 0: this level's own.
  int threshold_resolution = 0;
  ThresholdEstimate estimate;
  // The threshold was estimated before, over the whole volume, and given (a carve in tiles:
  // carve/tiling.h); `estimate` is then empty.
  bool threshold_given = false;
  // CarveOptions::threshold_seen_views, the first level: the threshold its first pass carved
  // with (from the tracks) and the pass's time; 0 where no first pass ran.
  double first_pass_threshold = 0.0;
  double first_pass_seconds = 0.0;
  int64_t protected_kept = 0;  // evaluations that kept a protected voxel found inconsistent
  // Voxels deeper in the coarser level's solid than CarveOptions::lod_carve_depth (held).
  int64_t interior_held = 0;
  Eigen::Vector3i dimensions = Eigen::Vector3i::Zero();
  int64_t start_solid = 0;  // solid voxels when the level began (after refinement and hull)
  int64_t carved = 0;            // by every means: hull, sight lines, colour, specks
  int64_t free_space_carved = 0; // of them, by the sparse points' sight lines (level start)
  int64_t evaluated = 0;
  int64_t final_solid = 0;
  double seconds = 0.0;        // set-up (rays) and carving
  double setup_seconds = 0.0;  // of which set-up: refinement, visual hull, rays, queue
};

// `levels` = kAutomaticLevels: as many levels as keep the coarsest at kMinAutomaticResolution
// voxels or more along the longest axis (resolution halved while it is even and its half is at
// least that): 128 -> 64, 128; 256 -> 64, 128, 256; 96 or less -> one level.
constexpr int kAutomaticLevels = 0;
constexpr int kMinAutomaticResolution = 64;
int AutomaticLevels(int resolution);

// The resolutions of `levels` levels ending at `resolution`, coarsest first, each half the next
// (kAutomaticLevels: AutomaticLevels(resolution) of them). False, with a reason, when
// `resolution` is not divisible by 2^(levels - 1), when the coarsest level would have fewer than
// 4 voxels along the longest axis, or when levels < 0 or > 8.
bool LevelResolutions(int resolution, int levels, std::vector<int>* resolutions,
                      std::string* reason);

// The next level's starting volume: every voxel of `fine` whose parent in `coarse` (the voxel
// holding it, at half the resolution) lies within `band` coarse voxels (26-neighbourhood, band
// steps) of a solid coarse voxel is solid. `fine` must have the coarse grid's origin and half its
// voxel size, with at most twice its voxels along each axis (CHECKed; VoxelGrid gives this for
// resolutions r and 2r over one box).
Volume RefineVolume(const Volume& coarse, const VoxelGrid& fine, int band = 1);

// The voxels of `fine` (the coarse grid halved, as for RefineVolume) whose parent lies more than
// `depth` coarse voxels inside the solid of `coarse`: every coarse voxel within `depth` steps
// (26-neighbourhood) of it is solid and inside the grid (CarveOptions::lod_carve_depth). Sorted
// indices into `fine`; none for depth <= 0.
std::vector<int64_t> DeepInteriorVoxels(const Volume& coarse, const VoxelGrid& fine, int depth);

// DeepInteriorVoxels for part of the finer grid: `fine` is the region of it that starts at voxel
// `offset` (VoxelGrid::Region); indices into the region.
std::vector<int64_t> DeepInteriorRegion(const Volume& coarse, const VoxelGrid& fine,
                                        const Eigen::Vector3i& offset, int depth);

// RefineVolume for part of the finer grid: `fine` is the region of it that starts at voxel
// `offset` (VoxelGrid::Region), and gets the same voxels as that part of RefineVolume's volume.
Volume RefineRegion(const Volume& coarse, const VoxelGrid& fine, const Eigen::Vector3i& offset,
                    int band = 1);

// `volume` with every voxel within `band` voxels (26-neighbourhood, band steps) of a solid one
// solid: what RefineVolume starts a finer level from, at the coarse level's voxels.
Volume DilateSolid(const Volume& volume, int band);

}  // namespace raycarve
