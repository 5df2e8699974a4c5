#include "carve/tiling.h"

#include <algorithm>
#include <memory>
#include <utility>

#include <glog/logging.h>

#include "calib/ray_box.h"
#include "carve/block_occupancy.h"
#include "carve/carver_internal.h"
#include "carve/level_of_detail.h"
#include "carve/ray_image.h"
#include "carve/view_workers.h"

namespace raycarve {
namespace {

int NumLevels(const CarveOptions& options) {
  std::vector<int> resolutions;
  std::string reason;
  if (!LevelResolutions(options.resolution, options.lod_levels, &resolutions, &reason)) return 0;
  return static_cast<int>(resolutions.size());
}

// The bit of voxel `index` in a packed vector.
bool Bit(const std::vector<uint64_t>& bits, int64_t index) {
  return ((bits[index >> 6] >> (index & 63)) & 1) != 0;
}
void SetBit(std::vector<uint64_t>* bits, int64_t index) {
  (*bits)[index >> 6] |= uint64_t{1} << (index & 63);
}

}  // namespace

bool CheckTiling(const Eigen::AlignedBox3d& box,
                 const CarveOptions& options,
                 const Eigen::Vector3i& tiles,
                 int overlap,
                 std::string* reason) {
  if ((tiles.array() < 1).any() || (tiles.array() > 64).any()) {
    *reason = "tiles must be 1 to 64 along each axis";
    return false;
  }
  if (overlap < 2 || overlap % 2 != 0) {
    *reason = "the tiles' overlap must be an even number of voxels, at least 2; got " +
              std::to_string(overlap);
    return false;
  }
  if (NumLevels(options) < 2) {
    *reason = "tiles start from the coarser levels of detail, and resolution " +
              std::to_string(options.resolution) +
              " with these levels has one: give a resolution of 128 or more (automatic levels) "
              "or --lod_levels 2 or more";
    return false;
  }
  const Eigen::Vector3i n = VoxelGrid(box, options.resolution).dimensions();
  for (int axis = 0; axis < 3; ++axis) {
    if (n[axis] / tiles[axis] < 4) {
      *reason = "a grid of " + std::to_string(n[axis]) + " voxels along axis " +
                std::string(1, "xyz"[axis]) + " cannot be cut into " + std::to_string(tiles[axis]) +
                " tiles of at least 4 voxels";
      return false;
    }
  }
  return true;
}

std::vector<TileRegion> SplitIntoTiles(const Eigen::Vector3i& dimensions,
                                       const Eigen::Vector3i& tiles,
                                       int overlap) {
  // Cut positions per axis: even (a coarse voxel is never split), the last at the grid's end.
  std::vector<int> cuts[3];
  for (int axis = 0; axis < 3; ++axis) {
    for (int k = 0; k <= tiles[axis]; ++k) {
      int cut = static_cast<int>(static_cast<int64_t>(dimensions[axis]) * k / tiles[axis]);
      if (k < tiles[axis]) cut -= cut % 2;
      cuts[axis].push_back(cut);
    }
  }
  std::vector<TileRegion> result;
  for (int z = 0; z < tiles.z(); ++z) {
    for (int y = 0; y < tiles.y(); ++y) {
      for (int x = 0; x < tiles.x(); ++x) {
        TileRegion tile;
        tile.index = static_cast<int>(result.size());
        const int k[3] = {x, y, z};
        for (int axis = 0; axis < 3; ++axis) {
          tile.core_lo[axis] = cuts[axis][k[axis]];
          tile.core_hi[axis] = cuts[axis][k[axis] + 1];
          tile.lo[axis] = std::max(0, tile.core_lo[axis] - overlap);
          tile.hi[axis] = std::min(dimensions[axis], tile.core_hi[axis] + overlap);
        }
        result.push_back(tile);
      }
    }
  }
  return result;
}

bool BoxInView(const CalibratedView& view, const Eigen::AlignedBox3d& box) {
  Eigen::Vector3d corners[8];
  for (int c = 0; c < 8; ++c) {
    corners[c] = box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(c)) - view.centre;
  }
  const Eigen::Matrix3d world_from_pixel = view.WorldFromPixel();
  const Eigen::Vector3d axis = world_from_pixel * Eigen::Vector3d(0.5 * view.width, 0.5 * view.height, 1.0);
  const Eigen::Vector3d rays[4] = {world_from_pixel * Eigen::Vector3d(0, 0, 1),
                                   world_from_pixel * Eigen::Vector3d(view.width, 0, 1),
                                   world_from_pixel * Eigen::Vector3d(view.width, view.height, 1),
                                   world_from_pixel * Eigen::Vector3d(0, view.height, 1)};
  // Inward normals: the four sides, then the camera's plane (the optical axis).
  Eigen::Vector3d normals[5];
  for (int i = 0; i < 4; ++i) {
    normals[i] = rays[i].cross(rays[(i + 1) % 4]);
    if (normals[i].dot(axis) < 0.0) normals[i] = -normals[i];
  }
  normals[4] = view.cam_from_world.rotation.conjugate() * Eigen::Vector3d::UnitZ();
  for (const Eigen::Vector3d& normal : normals) {
    bool any_inside = false;
    for (const Eigen::Vector3d& corner : corners) any_inside = any_inside || normal.dot(corner) >= 0.0;
    if (!any_inside) return false;
  }
  return true;
}

CoarseCarve CarveCoarseLevels(const std::vector<CalibratedView>& views,
                              const Eigen::AlignedBox3d& box,
                              const CarveOptions& options,
                              const std::function<void(const CarveProgress&)>& progress,
                              double progress_interval_seconds) {
  const int num_levels = NumLevels(options);
  CHECK_GE(num_levels, 2) << "CheckTiling";
  CarveStages stages;
  stages.last_level = num_levels - 2;
  stages.finish = false;
  std::unique_ptr<Volume> seen_through;
  stages.seen_through_out = &seen_through;
  CarveResult levels = CarveLevels(views, box, options, std::move(stages), progress,
                                   progress_interval_seconds);
  CoarseCarve result(levels.volume.grid());
  result.volume = std::move(levels.volume);
  result.statistics = std::move(levels.statistics);
  FinalLevelThresholds(views, box, options, seen_through.get(), &result.final_threshold,
                       &result.final_pattern_threshold);
  return result;
}

std::vector<CalibratedView> TileViews(const std::vector<CalibratedView>& views,
                                      const Volume& outside,
                                      const Eigen::AlignedBox3d& tile_box,
                                      int num_threads,
                                      int64_t* occluded_pixels) {
  const BlockOccupancy blocks(outside);
  const VoxelGrid& grid = outside.grid();
  const int threads = std::max(1, std::min(ResolveNumThreads(num_threads), 64));
  std::vector<CalibratedView> result = views;
  int64_t occluded = 0;
  for (CalibratedView& view : result) {
    RayImage rays(grid, view.WorldFromPixel(), view.centre, view.width, view.height, view.valid);
    rays.Initialise(outside, &blocks, threads);
    cv::Mat valid = view.valid.empty() ? cv::Mat(view.height, view.width, CV_8UC1, cv::Scalar(255))
                                       : view.valid.clone();
    uint8_t* pixels = valid.ptr<uint8_t>(0);
    for (int pixel = 0; pixel < rays.num_pixels(); ++pixel) {
      const int64_t hit = rays.CurrentVoxel(pixel);
      if (hit == RayImage::kNoVoxel || pixels[pixel] == 0) continue;
      const Eigen::Vector3d direction = rays.Direction(pixel);
      double tile_near = 0.0, tile_far = 0.0;
      if (!ClipRayToBox(view.centre, direction, tile_box, &tile_near, &tile_far)) continue;
      // The hit voxel lies outside the tile, so the ray is inside it either wholly before the
      // tile or wholly after: before, when it enters the voxel first.
      const Eigen::Vector3i voxel = grid.Voxel(hit);
      const Eigen::AlignedBox3d voxel_box(grid.Corner(voxel, 0), grid.Corner(voxel, 7));
      double voxel_near = 0.0, voxel_far = 0.0;
      if (!ClipRayToBox(view.centre, direction, voxel_box, &voxel_near, &voxel_far)) continue;
      if (voxel_near < tile_near) {
        pixels[pixel] = 0;
        ++occluded;
      }
    }
    view.valid = valid;
  }
  if (occluded_pixels != nullptr) *occluded_pixels = occluded;
  return result;
}

TileCarve CarveTile(const std::vector<CalibratedView>& views,
                    const Eigen::AlignedBox3d& box,
                    const CarveOptions& options,
                    const CoarseCarve& coarse,
                    const TileRegion& tile,
                    const std::function<void(const CarveProgress&)>& progress,
                    double progress_interval_seconds) {
  const int num_levels = NumLevels(options);
  CHECK_GE(num_levels, 2) << "CheckTiling";
  const VoxelGrid final_grid(box, options.resolution);
  const VoxelGrid region = final_grid.Region(tile.lo, tile.hi);
  // The coarse volume with its band, dilated once: refined with no further band it is the region's
  // start; less the coarse voxels that hold any of the region's, it is the outside.
  const Volume band = DilateSolid(coarse.volume, options.lod_band);
  const VoxelGrid& coarse_grid = band.grid();
  const Eigen::Vector3i coarse_lo = tile.lo / 2;
  const Eigen::Vector3i coarse_hi = ((tile.hi.array() + 1) / 2).matrix().cwiseMin(
      coarse_grid.dimensions());
  std::vector<uint64_t> bits = band.solid_bits();
  for (int z = coarse_lo.z(); z < coarse_hi.z(); ++z) {
    for (int y = coarse_lo.y(); y < coarse_hi.y(); ++y) {
      for (int x = coarse_lo.x(); x < coarse_hi.x(); ++x) {
        const int64_t index = coarse_grid.Index(Eigen::Vector3i(x, y, z));
        bits[index >> 6] &= ~(uint64_t{1} << (index & 63));
      }
    }
  }
  const Volume outside(coarse_grid, std::move(bits));
  int64_t occluded = 0;
  const std::vector<CalibratedView> tile_views =
      TileViews(views, outside, region.Box(), options.num_threads, &occluded);

  CarveStages stages;
  stages.first_level = num_levels - 1;
  stages.start = std::make_unique<Volume>(
      RefineRegion(band, region, tile.lo, /*band=*/0));
  stages.start_held = DeepInteriorRegion(coarse.volume, region, tile.lo, options.lod_carve_depth);
  stages.final_views = &tile_views;
  stages.final_thresholds_given = true;
  stages.final_threshold = coarse.final_threshold;
  stages.final_pattern_threshold = coarse.final_pattern_threshold;
  // The masks' hull is carved by the finish, over the whole volume: here an object pixel hidden
  // by the outside is no longer valid, and the hull would read its voxels as background.
  stages.final_visual_hull = false;
  stages.finish = false;
  CarveResult carved = CarveLevels(views, box, options, std::move(stages), progress,
                                   progress_interval_seconds);
  TileCarve result(region);
  result.volume = std::move(carved.volume);
  result.statistics = std::move(carved.statistics);
  result.occluded_pixels = occluded;
  return result;
}

std::vector<uint64_t> CoreBits(const Volume& volume, const TileRegion& tile) {
  const VoxelGrid& grid = volume.grid();
  CHECK(grid.dimensions() == tile.hi - tile.lo);
  std::vector<uint64_t> bits((tile.CoreVoxels() + 63) / 64, 0);
  int64_t out = 0;
  for (int z = tile.core_lo.z(); z < tile.core_hi.z(); ++z) {
    for (int y = tile.core_lo.y(); y < tile.core_hi.y(); ++y) {
      for (int x = tile.core_lo.x(); x < tile.core_hi.x(); ++x, ++out) {
        if (volume.IsSolid(grid.Index(Eigen::Vector3i(x, y, z) - tile.lo))) SetBit(&bits, out);
      }
    }
  }
  return bits;
}

Volume JoinTileCores(const VoxelGrid& grid,
                     const std::vector<TileRegion>& tiles,
                     const std::vector<std::vector<uint64_t>>& cores) {
  CHECK_EQ(tiles.size(), cores.size());
  std::vector<uint64_t> bits((grid.num_voxels() + 63) / 64, 0);
  for (size_t t = 0; t < tiles.size(); ++t) {
    if (cores[t].empty()) continue;
    const TileRegion& tile = tiles[t];
    CHECK_EQ(static_cast<int64_t>(cores[t].size()), (tile.CoreVoxels() + 63) / 64);
    int64_t in = 0;
    for (int z = tile.core_lo.z(); z < tile.core_hi.z(); ++z) {
      for (int y = tile.core_lo.y(); y < tile.core_hi.y(); ++y) {
        for (int x = tile.core_lo.x(); x < tile.core_hi.x(); ++x, ++in) {
          if (Bit(cores[t], in)) SetBit(&bits, grid.Index(Eigen::Vector3i(x, y, z)));
        }
      }
    }
  }
  return Volume(grid, std::move(bits));
}

CarveResult FinishTiledCarve(const std::vector<CalibratedView>& views,
                             const Eigen::AlignedBox3d& box,
                             const CarveOptions& options,
                             Volume joined,
                             const Volume& coarse,
                             double final_threshold,
                             double final_pattern_threshold,
                             const std::function<void(const CarveProgress&)>& progress,
                             double progress_interval_seconds) {
  const int num_levels = NumLevels(options);
  CHECK_GE(num_levels, 2) << "CheckTiling";
  CHECK(joined.grid().dimensions() == VoxelGrid(box, options.resolution).dimensions());
  CarveStages stages;
  stages.first_level = num_levels - 1;
  stages.start_held = DeepInteriorVoxels(coarse, joined.grid(), options.lod_carve_depth);
  stages.start = std::make_unique<Volume>(std::move(joined));
  stages.final_thresholds_given = true;
  stages.final_threshold = final_threshold;
  stages.final_pattern_threshold = final_pattern_threshold;
  return CarveLevels(views, box, options, std::move(stages), progress, progress_interval_seconds);
}

}  // namespace raycarve
