#include "carve/free_space.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <thread>

#include "carve/known_surface.h"

#include "carve/view_workers.h"

namespace raycarve {
namespace {

// A sight line's stop lies at most this many margins from its point along the line.
constexpr double kMaxSlant = 4.0;

}  // namespace

void SegmentVoxels(const VoxelGrid& grid,
                   const Eigen::Vector3d& from,
                   const Eigen::Vector3d& to,
                   std::vector<int64_t>* voxels) {
  const Eigen::Vector3d delta = to - from;
  const double length = delta.norm();
  if (!(length > 0.0)) return;
  const Eigen::Vector3d direction = delta / length;
  double t_near = 0.0, t_far = 0.0;
  if (!ClipRayToBox(from, direction, grid.Box(), &t_near, &t_far)) return;
  t_near = std::max(t_near, 0.0);
  t_far = std::min(t_far, length);
  if (!(t_near <= t_far)) return;
  const double size = grid.voxel_size();
  const Eigen::Vector3i& n = grid.dimensions();
  // Start inside the box (a hair past the entry, which lies on its faces).
  const Eigen::Vector3d entry = from + t_near * direction;
  Eigen::Vector3i voxel = grid.VoxelOf(entry);
  voxel = voxel.cwiseMax(0).cwiseMin(n - Eigen::Vector3i::Ones());
  // Amanatides-Woo: per axis, the ray parameter at which the segment leaves the current voxel
  // along that axis, and the parameter one voxel takes.
  Eigen::Vector3i step;
  Eigen::Vector3d t_max, t_delta;
  for (int a = 0; a < 3; ++a) {
    if (direction[a] > 0.0) {
      step[a] = 1;
      const double boundary = grid.origin()[a] + (voxel[a] + 1) * size;
      t_max[a] = (boundary - from[a]) / direction[a];
      t_delta[a] = size / direction[a];
    } else if (direction[a] < 0.0) {
      step[a] = -1;
      const double boundary = grid.origin()[a] + voxel[a] * size;
      t_max[a] = (boundary - from[a]) / direction[a];
      t_delta[a] = -size / direction[a];
    } else {
      step[a] = 0;
      t_max[a] = std::numeric_limits<double>::infinity();
      t_delta[a] = std::numeric_limits<double>::infinity();
    }
  }
  while (true) {
    voxels->push_back(grid.Index(voxel));
    int a = 0;
    if (t_max[1] < t_max[a]) a = 1;
    if (t_max[2] < t_max[a]) a = 2;
    if (t_max[a] > t_far) break;
    voxel[a] += step[a];
    if (voxel[a] < 0 || voxel[a] >= n[a]) break;
    t_max[a] += t_delta[a];
  }
}

namespace {

// Carves every solid voxel that a line passes through, but those holding a surface point and
// those in `keep`: `draw(k, &voxels)` appends line k's voxels (of `count`) and says whether it
// crossed the grid. Lines are drawn on `num_threads` threads and their voxels carved in index
// order, so the result does not depend on the count.
FreeSpaceStatistics CarveLines(size_t count,
                               const std::function<bool(size_t, std::vector<int64_t>*)>& draw,
                               const std::vector<SurfacePoint>& points,
                               const std::vector<int64_t>& keep,
                               Volume* volume,
                               int num_threads) {
  const auto start = std::chrono::steady_clock::now();
  FreeSpaceStatistics statistics;
  const VoxelGrid& grid = volume->grid();
  const int threads = std::max(1, std::min<int>(ResolveNumThreads(num_threads), 64));
  // Per thread: a bit per voxel that some line passed through while solid.
  const size_t words = static_cast<size_t>((grid.num_voxels() + 63) / 64);
  std::vector<std::vector<uint64_t>> passed(threads);
  std::vector<int64_t> lines(threads, 0);
  auto find = [&](int thread) {
    std::vector<uint64_t>& bits = passed[thread];
    bits.assign(words, 0);
    std::vector<int64_t> voxels;
    for (size_t k = thread; k < count; k += threads) {
      voxels.clear();
      if (draw(k, &voxels)) ++lines[thread];
      for (int64_t index : voxels) {
        if (volume->IsSolid(index)) bits[index >> 6] |= uint64_t{1} << (index & 63);
      }
    }
  };
  std::vector<std::thread> workers;
  for (int thread = 1; thread < threads; ++thread) workers.emplace_back(find, thread);
  find(0);
  for (std::thread& worker : workers) worker.join();
  // A voxel holding a point stays: a line that meets it passes the surface at a slant (or one of
  // the two is wrong).
  std::vector<uint64_t> kept(words, 0);
  for (int64_t index : SurfacePointVoxels(grid, points)) kept[index >> 6] |= uint64_t{1} << (index & 63);
  for (int64_t index : keep) kept[index >> 6] |= uint64_t{1} << (index & 63);
  std::vector<int64_t> exposed;
  for (size_t w = 0; w < words; ++w) {
    uint64_t word = 0;
    for (int thread = 0; thread < threads; ++thread) word |= passed[thread][w];
    word &= ~kept[w];
    while (word != 0) {
      const int bit = __builtin_ctzll(word);
      word &= word - 1;
      exposed.clear();
      volume->Carve(static_cast<int64_t>(w) * 64 + bit, &exposed);
      ++statistics.carved;
    }
  }
  for (int64_t lines_drawn : lines) statistics.sight_lines += lines_drawn;
  statistics.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return statistics;
}

// Whether the line from `from` (above the ground's plane) along `direction` passes down through
// the plane where the plane is ground (the crossing at any distance along the line).
bool CrossesOntoGround(const GroundMap& ground, const Eigen::Vector3d& from,
                       const Eigen::Vector3d& direction) {
  const double above = ground.Height(from), fall = above - ground.Height(from + direction);
  return above > 0.0 && fall > 0.0 &&
         ground.At(from + (above / fall) * direction) == GroundMap::Foot::kGround;
}

}  // namespace

FreeSpaceStatistics CarveFreeSpace(const std::vector<CalibratedView>& views,
                                   const std::vector<SurfacePoint>& points,
                                   double margin_voxels,
                                   Volume* volume,
                                   int num_threads,
                                   const Ground& ground) {
  const VoxelGrid& grid = volume->grid();
  const double margin = margin_voxels * grid.voxel_size();
  std::unique_ptr<GroundMap> ground_map;
  if (!ground.empty()) ground_map = std::make_unique<GroundMap>(ground);
  std::atomic<int64_t> through_ground{0};
  // One line per (point, view): the k-th point's views in turn.
  std::vector<std::pair<uint32_t, uint32_t>> sightings;
  for (size_t p = 0; p < points.size(); ++p) {
    for (size_t k = 0; k < points[p].views.size(); ++k) sightings.emplace_back(p, k);
  }
  const auto draw = [&](size_t index, std::vector<int64_t>* voxels) {
    const SurfacePoint& point = points[sightings[index].first];
    // The side of the surface the point was seen from: the mean direction to its views (on a
    // ring of cameras around a plane, its normal).
    Eigen::Vector3d facing = Eigen::Vector3d::Zero();
    for (int v : point.views) facing += (views[v].centre - point.xyz).normalized();
    if (!(facing.norm() > 0.0)) return false;
    facing.normalize();
    const Eigen::Vector3d& centre = views[point.views[sightings[index].second]].centre;
    if (ground_map != nullptr && -ground_map->Height(point.xyz) > ground.depth &&
        CrossesOntoGround(*ground_map, centre, point.xyz - centre)) {
      ++through_ground;
      return false;
    }
    const Eigen::Vector3d to_point = point.xyz - centre;
    const double length = to_point.norm();
    // The line stops `margin` above that plane (at most kMaxSlant margins along the line): a
    // line that meets the surface at a slant would otherwise cut the surface beside the point.
    const double rise = -to_point.dot(facing) / length;
    if (!(rise > 0.0)) return false;
    const double stop = margin / std::max(rise, 1.0 / kMaxSlant);
    if (!(length > stop)) return false;
    SegmentVoxels(grid, centre, centre + (1.0 - stop / length) * to_point, voxels);
    return !voxels->empty();
  };
  FreeSpaceStatistics statistics = CarveLines(sightings.size(), draw, points, {}, volume,
                                              num_threads);
  statistics.through_ground = through_ground;
  return statistics;
}

FreeSpaceStatistics CarveDistantRays(const std::vector<CalibratedView>& views,
                                     const std::vector<DistantRay>& rays,
                                     const std::vector<SurfacePoint>& points,
                                     double margin_voxels,
                                     const std::vector<int64_t>& keep,
                                     Volume* volume,
                                     int num_threads,
                                     const std::vector<cv::Mat>* known_depth,
                                     const Ground& ground) {
  const VoxelGrid& grid = volume->grid();
  std::unique_ptr<GroundMap> ground_map;
  if (!ground.empty()) ground_map = std::make_unique<GroundMap>(ground);
  std::atomic<int64_t> through_ground{0};
  std::vector<cv::Mat> made;
  if (known_depth == nullptr) made = KnownSurfaceDepths(views, grid, points);
  const std::vector<cv::Mat>& known = known_depth != nullptr ? *known_depth : made;
  const Eigen::AlignedBox3d box = grid.Box();
  const double beyond = box.diagonal().norm();
  const auto draw = [&](size_t index, std::vector<int64_t>* voxels) {
    const DistantRay& ray = rays[index];
    const CalibratedView& view = views[ray.view];
    const Eigen::Vector3d& centre = view.centre;
    // Camera depth per unit along the ray.
    const double depth_rate = (view.cam_from_world.rotation * ray.direction).z();
    if (!(depth_rate > 0.0)) return false;
    if (ground_map != nullptr && std::isinf(ray.length) &&
        CrossesOntoGround(*ground_map, centre, ray.direction)) {
      ++through_ground;
      return false;
    }
    double length = std::min(ray.length, (box.center() - centre).norm() + beyond);
    if (!known[ray.view].empty()) {
      const Eigen::Vector2d pixel = view.Project(centre + ray.direction);
      const int col = static_cast<int>(std::floor(pixel.x())), row = static_cast<int>(std::floor(pixel.y()));
      if (col >= 0 && row >= 0 && col < known[ray.view].cols && row < known[ray.view].rows) {
        const float depth = known[ray.view].at<float>(row, col);
        if (depth > 0.0f) length = std::min(length, depth / depth_rate - margin_voxels * grid.voxel_size());
      }
    }
    if (!(length > 0.0)) return false;
    SegmentVoxels(grid, centre, centre + length * ray.direction, voxels);
    return !voxels->empty();
  };
  FreeSpaceStatistics statistics = CarveLines(rays.size(), draw, points, keep, volume, num_threads);
  statistics.through_ground = through_ground;
  return statistics;
}

}  // namespace raycarve
