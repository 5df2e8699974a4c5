#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "calib/calibrated_view.h"
#include "carve/consistency.h"
#include "carve/volume.h"
#include "carve/voxel_grid.h"

namespace raycarve {

// The fewest judged surface points from which EstimateThreshold takes a threshold.
constexpr int kMinThresholdPoints = 20;

// A point known to lie on the object's surface (a reliable COLMAP sparse point) and the views
// that observed it (indices into the carve's views).
struct SurfacePoint {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  std::vector<int> views;
};

// The distribution of a consistency test's error over voxels that hold a known surface point
// ("surface") and over voxels `kFrontOffsetVoxels` voxels in front of it, towards the mean of
// its views' centres ("front": empty space from which the views see different parts of the
// surface), at one grid. Each voxel is judged as the carve would judge it once the space in
// front of the surface is carved: per view of the point's track, the usable pixels (valid, on the
// object where there is a mask) whose ray through the pixel centre meets the voxel's cube.
struct ThresholdEstimate {
  static constexpr double kFrontOffsetVoxels = 2.0;
  // Without masks: a wrongly carved surface voxel is allowed to be this many times as likely as
  // a kept front voxel. Known surface (CarveOptions::protect_surface_points) stops a wrong carve
  // from running away, while every kept front voxel is a floater in the model that also hides
  // what lies behind it (measured on the generated scenes: 1 keeps floaters, 3 and 5 about equal).
  static constexpr double kFrontWeight = 3.0;
  // Errors at or below this (RGB) are agreement to the last quantisation step: a point whose
  // surface and front voxels both agree so well (a plain or saturated region) says nothing about
  // where to put the threshold, and the no-mask rule leaves it out.
  static constexpr double kNoEvidence = 1.0;
  // Judged from every photo that sees it (ThresholdRule::seen_through), a point costs a sight
  // line and a footprint per photo: at most this many points are judged then (every k-th), a
  // sample that fixes an equal-error point to well within a quantisation step while a project of
  // 100,000 points and 500 photos stays at seconds.
  static constexpr size_t kMaxSeenThroughPoints = 5000;

  // surface points inside the grid with at least min_views views (judged from the photos that
  // see them: those sampled, at most kMaxSeenThroughPoints)
  int points_in_grid = 0;
  int points_judged = 0;   // of them, those whose voxel had pixels in at least min_views views
  int uninformative = 0;   // of them, those whose surface and front errors are both <= kNoEvidence
  // Summed over the points in the grid: the views each was judged from, and its track's views
  // (more judged than in the tracks where ThresholdRule::seen_through widened them).
  int64_t views_judged = 0;
  int64_t track_views = 0;
  // Their means over the points in the grid (0 without points).
  double ViewsPerPoint() const {
    return points_in_grid > 0 ? double(views_judged) / points_in_grid : 0.0;
  }
  double TrackViewsPerPoint() const {
    return points_in_grid > 0 ? double(track_views) / points_in_grid : 0.0;
  }
  std::vector<double> surface_errors;  // sorted ascending
  std::vector<double> front_errors;    // sorted ascending (voxels inside the grid only)
  double quantile = 0.0;   // the share of surface voxels the threshold keeps
  double threshold = 0.0;  // the chosen threshold (RGB units); see EstimateThreshold
  // With kPatchCorrelation: 1 - NCC of the textured voxels among them (sorted), and the chosen
  // pattern threshold.
  std::vector<double> surface_pattern_errors;
  std::vector<double> front_pattern_errors;
  double pattern_threshold = 0.0;
  // Per front voxel: (error, pattern error or -1), for FrontCarved.
  std::vector<std::pair<double, double>> front_flags;

  bool masked = false;     // which rule chose the threshold (EstimateThreshold)

  // The q-quantile (0..1) of sorted `values` by linear interpolation; 0 when empty.
  static double Quantile(const std::vector<double>& values, double q);
  // The weighted equal-error threshold of two sorted lists: the smallest t (a value of either) at
  // which the share of `surface` above t is at most front_weight x the share of `front` at or
  // below t.
  static double EqualError(const std::vector<double>& surface,
                           const std::vector<double>& front,
                           double front_weight = 1.0);
  // Share of front voxels the threshold would carve (error above it; with patterns, also those
  // whose pattern error exceeds the pattern threshold).
  double FrontCarved() const;
  std::string Summary() const;
};

// How EstimateThreshold measures and chooses.
struct ThresholdRule {
  ConsistencyMethod test_method = ConsistencyMethod::kMeanColour;
  int min_views = 2;
  // The views have object masks, so the visual hull has removed the empty space the views see
  // against the background.
  bool masked = false;
  bool correct_view_count = false;  // CarveOptions::correct_view_count
  double quantile = 0.99;         // with masks: the share of the surface voxels kept
  double fallback = 0.0;          // the threshold when too few points can be judged
  double pattern_fallback = 0.0;  // likewise the pattern threshold
  int min_points = kMinThresholdPoints;
  // Without masks, when set: each point is judged from every view that sees it through this
  // volume (the first pass of the carve's coarsest level: CarveOptions::threshold_seen_views),
  // not only from its track. A SIFT track is the few neighbouring photos that matched the
  // point; the carve judges a voxel from every photo that sees it, so a threshold measured on the
  // tracks alone is measured on easier evidence than the carve meets (see SeenThrough).
  const Volume* seen_through = nullptr;
};

// The views (indices into `views`) from whose centre the segment to `point` passes no solid
// voxel of `volume` farther than `margin` (world units) from the point, with the point in front
// of the view and inside its frame, together with `track` (views known to see it).
std::vector<int> SeenThrough(const std::vector<CalibratedView>& views,
                             const Volume& volume,
                             const Eigen::Vector3d& point,
                             double margin,
                             const std::vector<int>& track);

// Measures the errors of rule.test_method at `grid` over `points` (see ThresholdEstimate) and
// chooses the threshold (likewise the pattern threshold, from the textured voxels):
// - masked: the `quantile` of the surface voxels' errors, the smallest threshold that keeps
//   that share of them. What colour leaves is bounded by the hull, while a wrongly carved surface
//   voxel leaves a hole that the voxels behind it, seen through it, widen: the errors cost
//   unequally.
// - not masked: colour alone must carve all of the empty space: the smallest threshold at which
//   the share of surface voxels carved is at most kFrontWeight times the share of front voxels
//   kept (EqualError).
// `fallback` (`pattern_fallback`) is used when fewer than `min_points` points (textured points)
// could be judged.
ThresholdEstimate EstimateThreshold(const std::vector<CalibratedView>& views,
                                    const VoxelGrid& grid,
                                    const std::vector<SurfacePoint>& points,
                                    const ThresholdRule& rule);

// The statistics of one voxel in one view as EstimateThreshold gathers them: the usable pixels
// of `view` whose ray meets the cube of `voxel` (added to `stats`).
void GatherVoxelPixels(const CalibratedView& view,
                       const VoxelGrid& grid,
                       const Eigen::Vector3i& voxel,
                       ViewColourStats* stats);

// The indices of the voxels of `grid` holding a point of `points` (sorted, unique; points
// outside the grid are skipped).
std::vector<int64_t> SurfacePointVoxels(const VoxelGrid& grid,
                                        const std::vector<SurfacePoint>& points);

// Per view (of `views`, which the points' views index), its pixels of the points it saw that lie
// in front of it (COLMAP coordinates).
std::vector<std::vector<Eigen::Vector2d>> SurfacePointPixels(const std::vector<CalibratedView>& views,
                                                             const std::vector<SurfacePoint>& points);

}  // namespace raycarve
