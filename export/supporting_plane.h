#pragma once
// The plane an object stands on (a table, the ground), from the sparse points. PCL stays inside
// the .cc file.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/photos_up.h"
#include "carve/ground.h"

namespace raycarve {
namespace exporter {

// A plane within this many degrees of the photos' up is level (ground, a table). A narrow arc of
// cameras looking down tilts their mean up towards the object (by the cameras' pitch at most);
// a floor and a wall are 90 degrees apart.
constexpr double kMaxLevelAngle = 45.0;

struct SupportingPlane {
  bool found = false;
  // The plane n . x + offset = 0, n a unit vector pointing to the side most cameras are on.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double offset = 0.0;
  double tolerance = 0.0;      // world units: a point within it is on the plane
  int points = 0;              // points tried
  double on_plane_share = 0.0;  // of them, within `tolerance` of the plane
  double below_share = 0.0;     // beyond `tolerance` on the side away from the cameras
  double cameras_above_share = 0.0;
  // How widely the points on the plane spread along it against all the points (the square root of
  // the ratio of their 2-D covariances' determinants in the plane: their "areas"); negative where
  // not measured. A floor runs under and around what stands on it (>= 1); the cap of a ball, or
  // the ring where a pot stands, lies within what stands above it (a fraction).
  double spread_ratio = -1.0;
  // Found by the spread (kMinWideSupportSpread) with fewer than kMinSupportShareWithNothingBelow
  // of the points on it.
  bool found_by_spread = false;
  // Where the plane holding the most points was no support and a less dense one is: that densest
  // plane's shares (negative otherwise).
  double densest_on_share = -1.0;
  double densest_below_share = -1.0;
  // Degrees between the normal and the photos' up (EstimatePhotosUp); negative where the photos
  // say nothing of up. Where the densest plane was passed over for not being level, its angle.
  double angle_to_photos_up = -1.0;
  double densest_angle_to_photos_up = -1.0;
  PhotosUp photos_up;  // what the fit was given
  bool Level() const;
  std::string Summary() const;
};

// A support needs at least this share of the points on it, at most this share below it, and
// this share of the cameras above it.
constexpr double kMinSupportShare = 0.2;
constexpr double kMaxBelowShare = 0.1;
constexpr double kMinCamerasAbove = 0.8;
// A plane that is not the densest one, with nothing below it, is a support with this share on
// it: a ball's points hold a few percent on any plane (a cap as thick as the tolerance), a floor
// seen past an object much more.
constexpr double kMinSupportShareWithNothingBelow = 0.1;
// A level plane with fewer than that is a support where its points spread along it at least as
// widely as all the points do (SupportingPlane::spread_ratio), number kMinWideSupportPoints and
// leave at most kMaxBelowShareWide below it (a stray wrong match): a floor seen at a grazing angle
// (eye level) or past a large backdrop holds few points, but around the objects, not under them.
// A ball's bottom cap spreads a fifth as wide; a level plane tilted through the floor's points and
// the objects' feet leaves some of the floor's below it.
constexpr double kMinWideSupportSpread = 1.0;
constexpr int kMinWideSupportPoints = 20;
constexpr double kMaxBelowShareWide = 0.01;

// The plane n . x + offset = 0 (`normal`, `offset`) refitted by least squares on the points within
// `tolerance` of it and those up to kUnderReach tolerances under it (the side away from the
// normal), again until they settle (at most kMaxSettleRounds): a support has nothing under it, so
// the points just under a candidate are its own that a tilt left out (a plane through some of a
// floor's points and the foot of an object on it). False, the plane as given, where fewer than
// three points are within reach.
constexpr double kUnderReach = 3.0;
constexpr int kMaxSettleRounds = 8;
bool SettleOnPoints(const std::vector<Eigen::Vector3d>& points, double tolerance,
                    Eigen::Vector3d* normal, double* offset);

// The plane holding the most of `points` within `tolerance` (RANSAC with PCL's plane model, a
// fixed seed, refined by least squares on its inliers), oriented towards the majority of
// `cameras` (their centres), and whether it is a support: kMinSupportShare of the points on it,
// at most kMaxBelowShare of them below it, and kMinCamerasAbove of the cameras above. Where that
// densest plane is no support, the plane holding the most points among those with at most
// kMaxBelowShare below and kMinCamerasAbove of the cameras above (planes through random triples,
// a fixed seed), settled on the points just under it (SettleOnPoints), if it holds
// kMinSupportShareWithNothingBelow: wrong matches along a repeated
// pattern, or the sides of a large object, can outnumber the ground's points on some tilted
// plane. Otherwise the densest plane, not found. Fewer than 20 points: not found.
// Where the photos know up (`up.Known()`), the ground is level with it: a support within
// kMaxLevelAngle of up is taken before one that is not (a backdrop wall behind the object, with
// the cameras in front of it, passes every other test and can hold more points than the floor);
// one that is not level is taken only where no level plane holds
// kMinSupportShareWithNothingBelow. A level plane with fewer points that spreads them as widely as
// all the points (kMinWideSupportSpread, kMinWideSupportPoints) is a support too.
SupportingPlane FitSupportingPlane(const std::vector<Eigen::Vector3d>& points,
                                   const std::vector<Eigen::Vector3d>& cameras,
                                   const PhotosUp& up, double tolerance);

// The ground a found support makes (empty when `plane` is not a support): the points of
// `points` on the plane (within its tolerance) as the footprint, their convex hull as the outline,
// the feet of the points of `hole_points` below it as holes, all reaching twice the median
// spacing between neighbours on the plane; `depth` the plane's tolerance. (A hole says the photos
// saw through the plane: only points a third photo checked say so, where there are enough; a
// wrong match between two photos lies anywhere.)
// `checked` (parallel to `points`, empty: all) says which points a third photo checked. A point
// on the plane that no third photo checked and that has no other point of the plane within two
// reaches (their discs would not touch) is a lone wrong match, not ground: it is left out of the
// footprint and the outline (Ground::lone_points), where one such point far past the ground's edge
// would stretch the convex outline over empty space.
Ground GroundUnder(const SupportingPlane& plane, const std::vector<Eigen::Vector3d>& points,
                   const std::vector<Eigen::Vector3d>& hole_points,
                   const std::vector<bool>& checked = {});

}  // namespace exporter
}  // namespace raycarve
