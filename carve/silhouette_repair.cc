#include "carve/silhouette_repair.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "carve/block_occupancy.h"
#include "carve/ray_image.h"
#include "carve/view_workers.h"
#include "carve/visual_hull.h"
#include "carve/voxel_grid.h"

namespace raycarve {
namespace {

constexpr double kWindowVoxels = 3.0;  // the first window's radius, in projected voxel widths
constexpr int kMaxWindowPixels = 64;
constexpr int kMinNeighbours = 5;  // depths around a lost pixel that make a median
constexpr double kRimVoxels = 1.5;  // the silhouette's rim left alone, in projected voxel widths

std::unique_ptr<RayImage> MakeRays(const CalibratedView& view, const Volume& volume,
                                   const BlockOccupancy& blocks, int num_threads) {
  const Eigen::Matrix3d world_from_pixel = view.WorldFromPixel();
  const cv::Mat usable = view.valid.empty() ? view.mask : (view.valid & view.mask);
  auto rays = std::make_unique<RayImage>(volume.grid(), world_from_pixel, view.centre, view.width,
                                         view.height, usable);
  rays->Initialise(volume, &blocks, num_threads);
  return rays;
}

// The median of `values` (reordered); `values` is not empty.
float Median(std::vector<float>* values) {
  const size_t middle = values->size() / 2;
  std::nth_element(values->begin(), values->begin() + middle, values->end());
  return (*values)[middle];
}

bool IsSet(const std::vector<uint64_t>& bits, int64_t index) {
  return ((bits[index >> 6] >> (index & 63)) & 1) != 0;
}

// A membrane of one voxel per ray is a staircase whose steps may touch only along an edge. Seen
// from another photo, or taken by the mesh's iso-surface, such a pair leaves a gap; for each
// restored voxel and each solid voxel diagonal to it in one of the three axis planes whose two
// shared face neighbours are both empty, one of those (a hull voxel) is made solid too, and
// checked in turn. Returns how many voxels that adds.
int64_t BridgeDiagonalGaps(const VoxelGrid& grid, const Volume& hull,
                           std::vector<int64_t> restored, std::vector<uint64_t>* solid) {
  int64_t added = 0;
  while (!restored.empty()) {
    const int64_t voxel = restored.back();
    restored.pop_back();
    const Eigen::Vector3i cell = grid.Voxel(voxel);
    for (int u = 0; u < 3; ++u) {
      for (int w = u + 1; w < 3; ++w) {
        for (int su = -1; su <= 1; su += 2) {
          for (int sw = -1; sw <= 1; sw += 2) {
            Eigen::Vector3i diagonal = cell, first = cell, second = cell;
            diagonal[u] += su;
            diagonal[w] += sw;
            first[u] += su;
            second[w] += sw;
            if (!grid.Contains(diagonal)) continue;  // then first and second are inside too
            const int64_t d = grid.Index(diagonal), a = grid.Index(first), b = grid.Index(second);
            if (!IsSet(*solid, d) || IsSet(*solid, a) || IsSet(*solid, b)) continue;
            const int64_t bridge = hull.IsSolid(a) ? a : (hull.IsSolid(b) ? b : -1);
            if (bridge < 0) continue;
            (*solid)[bridge >> 6] |= uint64_t{1} << (bridge & 63);
            restored.push_back(bridge);
            ++added;
          }
        }
      }
    }
  }
  return added;
}

}  // namespace

std::string SilhouetteRepairSummary::Summary() const {
  std::ostringstream out;
  out << "silhouettes: " << lost_pixels << " of " << object_pixels << " object pixels of " << views
      << " masked views had lost the model to carving (each view after the repairs of those "
      << "before it); " << restored_voxels
      << " voxels restored (" << bridging_voxels << " of them bridging diagonal steps) in "
      << seconds << " s";
  if (outside_hull_pixels > 0) {
    out << " (" << outside_hull_pixels << " more object pixels miss the visual hull: masks that "
        << "disagree)";
  }
  return out.str();
}

namespace {

// The median depth of the model's surface around pixel (row, col) in `depth` (0: no surface), in
// a window that doubles from `first_radius` until it holds kMinNeighbours pixels; -1 when none
// within kMaxWindowPixels. `around` is a buffer.
float DepthAround(const cv::Mat& depth,
                  int row,
                  int col,
                  int first_radius,
                  std::vector<float>* around_buffer) {
  std::vector<float>& around = *around_buffer;
  float target = -1.0f;
  for (int radius = first_radius; target < 0.0f; radius *= 2) {
    around.clear();
    for (int r = std::max(0, row - radius); r <= std::min(depth.rows - 1, row + radius); ++r) {
      const float* line = depth.ptr<float>(r);
      for (int c = std::max(0, col - radius); c <= std::min(depth.cols - 1, col + radius); ++c) {
        if (line[c] > 0.0f) around.push_back(line[c]);
      }
    }
    if (static_cast<int>(around.size()) >= kMinNeighbours) target = Median(&around);
    if (radius >= kMaxWindowPixels) break;
  }
  return target;
}

// Along pixel p's ray through the grid's box, the voxel of the visual hull nearest the depth
// `target` (the nearest hull voxel when target < 0); -1 when the ray meets no hull voxel.
int64_t HullVoxelNear(const CalibratedView& view, const RayImage& rays, int p, const VoxelGrid& grid,
                      const Volume& hull, float target) {
  const Eigen::AlignedBox3d box = grid.Box();
  const Eigen::Vector3d direction = rays.Direction(p);
  double t_near = 0.0, t_far = 0.0;
  if (!ClipRayToBox(view.centre, direction, box, &t_near, &t_far)) t_far = -1.0;
  const double step = 0.25 * grid.voxel_size() / direction.norm();
  int64_t best = -1;
  double best_gap = std::numeric_limits<double>::infinity();
  for (double t = t_near + 0.5 * step; t < t_far; t += step) {
    const Eigen::Vector3d point = view.centre + t * direction;
    const Eigen::Vector3i cell = grid.VoxelOf(point);
    if (!grid.Contains(cell)) continue;
    const int64_t index = grid.Index(cell);
    if (!hull.IsSolid(index)) continue;
    if (target < 0.0f) {
      best = index;  // no surface around: the hull's nearest voxel
      break;
    }
    const double gap = std::abs(view.Depth(point) - target);
    if (gap < best_gap) {
      best_gap = gap;
      best = index;
    }
  }
  return best;
}

}  // namespace

SilhouetteRepairSummary RepairSilhouettes(const std::vector<CalibratedView>& views,
                                          Volume* volume,
                                          int num_threads) {
  const auto start = std::chrono::steady_clock::now();
  SilhouetteRepairSummary summary;
  const VoxelGrid grid = volume->grid();
  Volume hull(grid);
  CarveVisualHull(views, &hull, num_threads);
  std::vector<uint64_t> solid = volume->solid_bits();
  const Eigen::AlignedBox3d box = grid.Box();
  std::vector<float> around;
  const int threads = std::max(1, std::min(ResolveNumThreads(num_threads), 64));
  // Remade only when a view restored voxels.
  std::unique_ptr<BlockOccupancy> blocks = std::make_unique<BlockOccupancy>(*volume);
  for (const CalibratedView& view : views) {
    if (view.mask.empty()) continue;
    ++summary.views;
    const std::unique_ptr<RayImage> rays = MakeRays(view, *volume, *blocks, threads);
    const double focal = 0.5 * (view.K(0, 0) + view.K(1, 1));
    const double voxel_pixels = focal * grid.voxel_size() / std::max(view.Depth(box.center()), 1e-9);
    // Only pixels at least kRimVoxels voxel widths inside the silhouette count as lost: at its
    // rim a voxel straddles the outline, and carving it is the grid's rounding, not a hole.
    const int rim = static_cast<int>(std::ceil(kRimVoxels * voxel_pixels));
    cv::Mat inside;
    cv::erode(view.mask, inside,
              cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * rim + 1, 2 * rim + 1)));
    if (!view.valid.empty()) inside &= view.valid;
    // Per pixel, the depth of the model's voxel its ray meets (0: none), and the lost pixels.
    cv::Mat depth = cv::Mat::zeros(view.height, view.width, CV_32F);
    std::vector<int> lost;
    for (int p = 0; p < rays->num_pixels(); ++p) {
      const int64_t voxel = rays->CurrentVoxel(p);
      if (inside.data[p] != 0) ++summary.object_pixels;
      if (voxel == RayImage::kNoVoxel) {
        if (inside.data[p] != 0) lost.push_back(p);
      } else {
        depth.at<float>(p / view.width, p % view.width) =
            static_cast<float>(view.Depth(grid.Centre(grid.Voxel(voxel))));
      }
    }
    if (lost.empty()) continue;
    const int first_radius = std::max(2, static_cast<int>(std::ceil(kWindowVoxels * voxel_pixels)));
    int64_t restored = 0;
    std::vector<int64_t> restored_here;
    for (int p : lost) {
      const int row = p / view.width, col = p % view.width;
      // The depth the surface around the hole has.
      const float target = DepthAround(depth, row, col, first_radius, &around);
      // Along the ray, the hull voxel nearest that depth (the nearest hull voxel when there is
      // none).
      const int64_t best = HullVoxelNear(view, *rays, p, grid, hull, target);
      if (best < 0) {
        ++summary.outside_hull_pixels;  // the masks disagree here: nothing was carved from it
        continue;
      }
      ++summary.lost_pixels;
      if (!IsSet(solid, best)) {
        solid[best >> 6] |= uint64_t{1} << (best & 63);
        ++restored;
        restored_here.push_back(best);
      }
      // The voxel now stops this ray; its depth serves the lost pixels next to it.
      depth.at<float>(row, col) = static_cast<float>(view.Depth(grid.Centre(grid.Voxel(best))));
    }
    const int64_t bridging = BridgeDiagonalGaps(grid, hull, std::move(restored_here), &solid);
    summary.bridging_voxels += bridging;
    restored += bridging;
    summary.restored_voxels += restored;
    if (restored > 0) {
      *volume = Volume(grid, solid);
      blocks = std::make_unique<BlockOccupancy>(*volume);
    }
  }
  summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace raycarve
