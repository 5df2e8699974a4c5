#include "carve/surface_evidence.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <limits>

#include "carve/footprint.h"
#include "carve/patch_correlation.h"

namespace raycarve {

double ThresholdEstimate::Quantile(const std::vector<double>& values, double q) {
  if (values.empty()) return 0.0;
  const double position = std::clamp(q, 0.0, 1.0) * (values.size() - 1);
  const size_t below = static_cast<size_t>(std::floor(position));
  const size_t above = std::min(values.size() - 1, below + 1);
  const double fraction = position - below;
  return values[below] * (1.0 - fraction) + values[above] * fraction;
}

double ThresholdEstimate::EqualError(const std::vector<double>& surface,
                                     const std::vector<double>& front,
                                     double front_weight) {
  if (surface.empty()) return 0.0;
  if (front.empty()) return surface.back();
  // Candidates: every value of either list; the first at which the share of surface voxels above
  // it is no longer larger than the share of front voxels at or below it.
  std::vector<double> candidates(surface);
  candidates.insert(candidates.end(), front.begin(), front.end());
  std::sort(candidates.begin(), candidates.end());
  for (double t : candidates) {
    const double surface_carved =
        static_cast<double>(surface.end() - std::upper_bound(surface.begin(), surface.end(), t)) /
        surface.size();
    const double front_kept =
        static_cast<double>(std::upper_bound(front.begin(), front.end(), t) - front.begin()) /
        front.size();
    if (surface_carved <= front_weight * front_kept) return t;
  }
  return candidates.back();
}

double ThresholdEstimate::FrontCarved() const {
  if (front_flags.empty()) return 0.0;
  int64_t carved = 0;
  for (const auto& [error, pattern_error] : front_flags) {
    carved += error > threshold || pattern_error > pattern_threshold;
  }
  return static_cast<double>(carved) / front_flags.size();
}

std::string ThresholdEstimate::Summary() const {
  std::ostringstream text;
  text << std::fixed << std::setprecision(1) << "threshold " << threshold << " ("
       << (masked ? "their 99% quantile: masks" : "weighted equal error: no masks") << ") from "
       << points_judged << " of " << points_in_grid
       << " surface points";
  if (views_judged > track_views) {
    text << " (judged from the " << std::setprecision(1) << ViewsPerPoint()
         << " photos a point that see it, tracks " << TrackViewsPerPoint() << ")";
  }
  text << ": surface voxels' error median " << Quantile(surface_errors, 0.5)
       << ", 90% " << Quantile(surface_errors, 0.9) << ", 95% " << Quantile(surface_errors, 0.95)
       << ", 99% " << Quantile(surface_errors, 0.99) << "; voxels " << kFrontOffsetVoxels
       << " in front: median " << Quantile(front_errors, 0.5) << ", "
       << std::setprecision(0) << 100.0 * FrontCarved() << "% carved";
  if (!surface_pattern_errors.empty()) {
    text << std::setprecision(2) << "; patterns (1 - NCC): threshold " << pattern_threshold
         << " from " << surface_pattern_errors.size() << " textured surface voxels (median "
         << Quantile(surface_pattern_errors, 0.5) << "), front median "
         << Quantile(front_pattern_errors, 0.5);
  }
  return text.str();
}

void GatherVoxelPixels(const CalibratedView& view,
                       const VoxelGrid& grid,
                       const Eigen::Vector3i& voxel,
                       ViewColourStats* stats) {
  const Footprint footprint = ComputeFootprint(view.P, view.width, view.height, grid, voxel);
  if (footprint.empty()) return;
  const Eigen::AlignedBox3d cube(grid.Corner(voxel, 0), grid.Corner(voxel, 7));
  const Eigen::Matrix3d world_from_pixel = view.WorldFromPixel();
  for (int row = footprint.row_min; row <= footprint.row_max; ++row) {
    const uint8_t* valid = view.valid.empty() ? nullptr : view.valid.ptr<uint8_t>(row);
    const uint8_t* mask = view.mask.empty() ? nullptr : view.mask.ptr<uint8_t>(row);
    const uint8_t* rgb = view.image.ptr<uint8_t>(row);
    for (int col = footprint.col_min; col <= footprint.col_max; ++col) {
      if ((valid != nullptr && valid[col] == 0) || (mask != nullptr && mask[col] == 0)) continue;
      const Eigen::Vector3d direction = world_from_pixel * Eigen::Vector3d(col + 0.5, row + 0.5, 1);
      double t_near = 0.0, t_far = 0.0;
      if (!ClipRayToBox(view.centre, direction, cube, &t_near, &t_far)) continue;
      stats->Add(Eigen::Vector3d(rgb[3 * col], rgb[3 * col + 1], rgb[3 * col + 2]));
    }
  }
}

std::vector<int> SeenThrough(const std::vector<CalibratedView>& views,
                             const Volume& volume,
                             const Eigen::Vector3d& point,
                             double margin,
                             const std::vector<int>& track) {
  const VoxelGrid& grid = volume.grid();
  const Eigen::AlignedBox3d box = grid.Box();
  const double step = 0.5 * grid.voxel_size();
  std::vector<int> seen(track);
  for (int v = 0; v < static_cast<int>(views.size()); ++v) {
    if (std::find(track.begin(), track.end(), v) != track.end()) continue;
    const CalibratedView& view = views[v];
    if (view.Depth(point) <= 0.0) continue;
    const Eigen::Vector2d pixel = view.Project(point);
    if (!(pixel.x() >= 0.0 && pixel.y() >= 0.0 && pixel.x() < view.width &&
          pixel.y() < view.height)) {
      continue;
    }
    const Eigen::Vector3d offset = point - view.centre;
    const double distance = offset.norm();
    const Eigen::Vector3d direction = offset / distance;
    double t_near = 0.0, t_far = 0.0;
    bool blocked = false;
    if (ClipRayToBox(view.centre, direction, box, &t_near, &t_far)) {
      const double t_end = std::min(t_far, distance - margin);
      for (double t = t_near + 0.5 * step; t < t_end && !blocked; t += step) {
        blocked = volume.IsSolid(grid.VoxelOf(view.centre + t * direction));
      }
    }
    if (!blocked) seen.push_back(v);
  }
  return seen;
}

namespace {

// The points in the grid with at least `min_views` views; with `sample`, at most
// ThresholdEstimate::kMaxSeenThroughPoints of them, evenly spread over the list (every k-th).
std::vector<const SurfacePoint*> JudgedPoints(const VoxelGrid& grid,
                                              const std::vector<SurfacePoint>& points,
                                              int min_views,
                                              bool sample) {
  std::vector<const SurfacePoint*> eligible;
  for (const SurfacePoint& point : points) {
    if (grid.Contains(grid.VoxelOf(point.xyz)) && static_cast<int>(point.views.size()) >= min_views) {
      eligible.push_back(&point);
    }
  }
  const size_t limit = ThresholdEstimate::kMaxSeenThroughPoints;
  if (!sample || eligible.size() <= limit) return eligible;
  const size_t stride = (eligible.size() + limit - 1) / limit;
  std::vector<const SurfacePoint*> judged;
  for (size_t i = 0; i < eligible.size(); i += stride) judged.push_back(eligible[i]);
  return judged;
}

// Each point's voxel's error, and that of the voxel kFrontOffsetVoxels in front of it (towards
// the views that saw it), judged from the point's views, into `estimate`'s lists (sorted).
void MeasurePointErrors(const std::vector<CalibratedView>& views,
                        const VoxelGrid& grid,
                        const std::vector<SurfacePoint>& points,
                        ConsistencyMethod test_method,
                        int min_views,
                        bool correct_view_count,
                        const Volume* seen_through,
                        ThresholdEstimate* estimate_out) {
  ThresholdEstimate& estimate = *estimate_out;
  const ConsistencyTest test(test_method, 0.0, min_views, 0.0, correct_view_count);
  std::vector<ViewColourStats> stats;
  // The error of `voxel` judged from `point`'s views, or a negative value when not judged.
  const bool patterns = test_method == ConsistencyMethod::kPatchCorrelation;
  double pattern_error = -1.0;  // of the last voxel error_of judged
  // Solid voxels this near the point may be the thickness a coarser volume keeps in front of it.
  const double margin =
      seen_through == nullptr
          ? 0.0
          : (ThresholdEstimate::kFrontOffsetVoxels + 1.0) * grid.voxel_size() +
                seen_through->grid().voxel_size();
  std::vector<int> point_views;
  auto error_of = [&](const Eigen::Vector3i& voxel) {
    stats.clear();
    for (int v : point_views) {
      ViewColourStats view_stats;
      view_stats.view = v;
      GatherVoxelPixels(views[v], grid, voxel, &view_stats);
      if (view_stats.count > 0) stats.push_back(view_stats);
    }
    const Consistency consistency = test.Evaluate(stats);
    pattern_error = -1.0;
    if (patterns && consistency.judged) {
      const PatchCorrelation patches =
          CorrelatePatches(views, grid.Centre(voxel), grid.voxel_size(), stats);
      if (patches.textured) pattern_error = patches.error();
    }
    return consistency.judged ? consistency.error : -1.0;
  };
  for (const SurfacePoint* judged : JudgedPoints(grid, points, min_views, seen_through != nullptr)) {
    const SurfacePoint& point = *judged;
    const Eigen::Vector3i voxel = grid.VoxelOf(point.xyz);
    ++estimate.points_in_grid;
    point_views = seen_through == nullptr
                      ? point.views
                      : SeenThrough(views, *seen_through, point.xyz, margin, point.views);
    estimate.views_judged += point_views.size();
    estimate.track_views += point.views.size();
    const double surface = error_of(voxel);
    if (surface < 0.0) continue;
    ++estimate.points_judged;
    estimate.surface_errors.push_back(surface);
    if (pattern_error >= 0.0) estimate.surface_pattern_errors.push_back(pattern_error);
    Eigen::Vector3d towards = Eigen::Vector3d::Zero();
    for (int v : point.views) towards += (views[v].centre - point.xyz).normalized();
    if (towards.norm() < 1e-9) continue;
    const Eigen::Vector3i front = grid.VoxelOf(
        point.xyz + towards.normalized() * ThresholdEstimate::kFrontOffsetVoxels * grid.voxel_size());
    if (!grid.Contains(front) || front == voxel) continue;
    const double front_error = error_of(front);
    if (front_error < 0.0) continue;
    if (surface <= ThresholdEstimate::kNoEvidence && front_error <= ThresholdEstimate::kNoEvidence) {
      ++estimate.uninformative;
    }
    estimate.front_errors.push_back(front_error);
    estimate.front_flags.emplace_back(front_error, pattern_error);
    if (pattern_error >= 0.0) estimate.front_pattern_errors.push_back(pattern_error);
  }
  std::sort(estimate.surface_errors.begin(), estimate.surface_errors.end());
  std::sort(estimate.front_errors.begin(), estimate.front_errors.end());
  std::sort(estimate.surface_pattern_errors.begin(), estimate.surface_pattern_errors.end());
  std::sort(estimate.front_pattern_errors.begin(), estimate.front_pattern_errors.end());
}

}  // namespace

ThresholdEstimate EstimateThreshold(const std::vector<CalibratedView>& views,
                                    const VoxelGrid& grid,
                                    const std::vector<SurfacePoint>& points,
                                    const ThresholdRule& rule) {
  const ConsistencyMethod test_method = rule.test_method;
  const bool masked = rule.masked;
  const double quantile = rule.quantile;
  const int min_points = rule.min_points;
  ThresholdEstimate estimate;
  estimate.quantile = quantile;
  const bool patterns = test_method == ConsistencyMethod::kPatchCorrelation;
  MeasurePointErrors(views, grid, points, test_method, rule.min_views, rule.correct_view_count,
                     masked ? nullptr : rule.seen_through, &estimate);
  estimate.masked = masked;
  auto choose = [&](const std::vector<double>& surface, const std::vector<double>& front) {
    return masked || front.empty() ? ThresholdEstimate::Quantile(surface, quantile)
                                   : ThresholdEstimate::EqualError(surface, front, ThresholdEstimate::kFrontWeight);
  };
  // The equal-error rule weighs only the points whose two voxels colour can tell apart at all:
  // as many exact agreements as there are uninformative pairs leave both lists (each list is
  // sorted, so they are its first values).
  const size_t drop = masked ? 0 : static_cast<size_t>(estimate.uninformative);
  const std::vector<double> rule_surface(
      estimate.surface_errors.begin() + std::min(drop, estimate.surface_errors.size()),
      estimate.surface_errors.end());
  const std::vector<double> rule_front(
      estimate.front_errors.begin() + std::min(drop, estimate.front_errors.size()),
      estimate.front_errors.end());
  estimate.threshold = estimate.points_judged >= min_points ? choose(rule_surface, rule_front)
                                                            : rule.fallback;
  estimate.pattern_threshold =
      static_cast<int>(estimate.surface_pattern_errors.size()) >= min_points
          ? choose(estimate.surface_pattern_errors, estimate.front_pattern_errors)
          : rule.pattern_fallback;
  if (!patterns) estimate.pattern_threshold = std::numeric_limits<double>::infinity();
  return estimate;
}

std::vector<int64_t> SurfacePointVoxels(const VoxelGrid& grid,
                                        const std::vector<SurfacePoint>& points) {
  std::vector<int64_t> voxels;
  voxels.reserve(points.size());
  for (const SurfacePoint& point : points) {
    const Eigen::Vector3i voxel = grid.VoxelOf(point.xyz);
    if (grid.Contains(voxel)) voxels.push_back(grid.Index(voxel));
  }
  std::sort(voxels.begin(), voxels.end());
  voxels.erase(std::unique(voxels.begin(), voxels.end()), voxels.end());
  return voxels;
}

std::vector<std::vector<Eigen::Vector2d>> SurfacePointPixels(const std::vector<CalibratedView>& views,
                                                             const std::vector<SurfacePoint>& points) {
  std::vector<std::vector<Eigen::Vector2d>> pixels(views.size());
  for (const SurfacePoint& point : points) {
    for (int v : point.views) {
      if (views[v].Depth(point.xyz) > 0.0) pixels[v].push_back(views[v].Project(point.xyz));
    }
  }
  return pixels;
}

}  // namespace raycarve
