#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "calib/reconstruction.h"

namespace raycarve {

// How the volume to carve is bounded from a model's sparse points. Sparse SfM points contain
// outliers (mismatches, points on the background far behind the object), so the box is robust:
// points are filtered by track length and reprojection error, each axis is trimmed at quantiles,
// and a margin is added.
// The largest --margin: a box a hundred times wider than the object carves nothing but space.
constexpr double kMaxMargin = 100.0;

struct BoundsOptions {
  // Points seen in fewer images than this are ignored.
  int min_track_length = 2;
  // Points whose mean reprojection error (pixels) exceeds this are ignored; <= 0 disables.
  double max_reprojection_error = 2.0;
  // The object is what the photos frame. A point framed by fewer photos than this share of the
  // best framed points' count (their 90th percentile) is the room around the object; such points
  // are dropped when they are more than twice trim_fraction of the points (a room, not a few
  // stray points, which the trim takes). 0 keeps every point. See ComputeBounds.
  double min_framed_share = 0.5;
  // Fraction of the remaining points dropped at each end of each axis (0 keeps the extremes).
  double trim_fraction = 0.01;
  // Added on every side, as a fraction of the trimmed box's largest extent.
  double margin = 0.1;
  // Fewer usable points than this cannot be trusted to span the object: an error asking for an
  // explicit box.
  int min_points = 20;

  // False, with the reason, when a field is out of its range.
  bool IsValid(std::string* reason) const;
};

struct Bounds {
  Eigen::AlignedBox3d box;
  bool is_explicit = false;     // given by the user, not computed
  bool around_focus = false;    // the box around the cameras' focus (CaptureLayout::focus_box)
  bool around_hull = false;     // narrowed to the masks' visual hull (VisualHullBox)
  Eigen::AlignedBox3d points_box;  // when around_hull: the box the sparse points gave
  // A scene's box narrowed to the sparse points its photos place in depth to a voxel
  // (ResolveSceneDepth): their number, of the points tried; 0 of 0 when not narrowed.
  int depth_resolved_points = 0;
  int depth_tried_points = 0;
  int num_points = 0;           // points in the model
  int num_used = 0;             // points that passed the filters
  int num_short_track = 0;      // dropped for track length
  int num_high_error = 0;       // dropped for reprojection error
  int num_unframed = 0;         // dropped as the room around the object (min_framed_share)
  int num_trimmed_outside = 0;  // used points outside the trimmed box (before the margin)

  std::string Summary() const;
};

// Bounds of `reconstruction`'s sparse points with `options` (which must be valid, CHECKed).
// Throws InputError naming `source` when the model has no 3D points, when the filters leave none
// (saying how many each filter dropped), or when the points span no volume.
Bounds ComputeBounds(const Reconstruction& reconstruction,
                     const BoundsOptions& options,
                     const std::string& source);

// An explicit box (for --bbox): throws InputError when a coordinate is not finite or min >= max
// on an axis.
Bounds ExplicitBounds(const Eigen::Vector3d& min, const Eigen::Vector3d& max);

// How the cameras of a capture stand, from their poses alone: around a point they all look at
// (an object-centred capture: a turntable, a walk around a statue) or facing one way (a scene: a
// facade, a room, a forward-facing capture).
struct CaptureLayout {
  // The point nearest every camera's optical axis (least squares), and the median distance of
  // the cameras from it.
  Eigen::Vector3d focus = Eigen::Vector3d::Zero();
  double camera_distance = 0.0;
  // Seen from the focus, the cameras' directions: the widest angle between one of them and
  // their mean (the cone they fill), and the widest gap between them going round the mean.
  double cone_half_angle_degrees = 0.0;
  double largest_gap_degrees = 360.0;
  // Cameras with the focus in front of them (positive depth), of all.
  int focus_in_front = 0;
  int cameras = 0;
  // Object-centred: the focus in front of every camera, and the cameras all round it (no gap
  // wider than kMaxObjectGapDegrees, the cone at least kMinRingConeDegrees: a ring at any
  // height) or over a wide arc (the cone at least kMinArcConeDegrees). A forward-facing grid
  // fills a narrow cone; a walk along a facade leaves a gap of half a turn.
  bool object_centred = false;
  // The sparse points that most photos would frame around the focus: within the cameras' median
  // half field of view of it (at camera_distance), trimmed at 2% per axis, plus 10% margin. Empty
  // when fewer than 20 points lie there.
  // Then grown to hold the occluders (FindOccluders) when there are at least kMinOccluderPoints.
  Eigen::AlignedBox3d focus_box;
  int focus_box_points = 0;
  int occluder_points = 0;
  std::string Summary() const;
};
constexpr double kMaxObjectGapDegrees = 150.0;
constexpr double kMinRingConeDegrees = 20.0;
constexpr double kMinArcConeDegrees = 60.0;

// Occluders: sparse points outside a box that hide points inside it from photos. A point hides
// in a photo that observes it when at least kOccludedPointsPerView points of the box that the
// photo does not observe (though they lie in its frame) project within kOccluderNeighbourhood of
// the photo's longer side of it and lie more than kOccluderDepthGap farther; it is an occluder
// when it hides so in at least kOccluderViews photos. (A point merely missed by the matcher in
// one photo does not make its neighbours occluders: it takes several behind one point, in two
// photos.)
constexpr double kOccluderNeighbourhood = 1.0 / 40.0;
constexpr double kOccluderDepthGap = 0.1;
constexpr int kOccludedPointsPerView = 2;
constexpr int kOccluderViews = 2;
constexpr int kMinOccluderPoints = 10;
std::vector<Eigen::Vector3d> FindOccluders(const Reconstruction& reconstruction,
                                           const Eigen::AlignedBox3d& box);

// How deep into a scene its photos resolve the carve's grid. A sparse point seen from cameras
// whose rays to it meet at an angle of at most alpha, at a pixel footprint w (its distance over
// the focal length in pixels, the median over its views), is placed in depth to about
// w / sin(alpha) per pixel of error. Where that exceeds kResolvedDepthVoxels voxels (the
// tolerance the model is measured at: the F-score's and holdout's depth agreement), colour cannot
// place a surface there either: moving it that far in depth moves it less than a pixel between
// the photos. Forward-facing captures see their background (a far wall, trees behind a facade)
// from a baseline small against its distance: a box that reaches it gets coarse voxels, and the
// carve fills the space in front of it with surfaces the photos cannot tell apart.
struct DepthResolution {
  int points = 0;      // points with 2+ views of known focal length, inside the box
  int resolved = 0;    // of them, placed in depth to kResolvedDepthVoxels per pixel or better
  double voxel = 0.0;  // the box's longest side over the resolution
  // The resolved points' box (trimmed at 2% per axis, 10% margin) within the given one; empty
  // when the box is kept: every point resolved, fewer than kMinResolvedShare of them or fewer
  // than 20, or a box no smaller.
  Eigen::AlignedBox3d box;
  std::string Summary() const;
};
constexpr double kResolvedDepthVoxels = 2.0;
constexpr double kMinResolvedShare = 0.5;
// `focal_px`: per image the focal length in pixels of its photo as loaded (images without one
// are not used).
DepthResolution ResolveSceneDepth(const Reconstruction& reconstruction,
                                  const std::map<image_t, double>& focal_px,
                                  const Eigen::AlignedBox3d& box, int resolution);

// Describes `reconstruction`'s cameras (at least 2 images; otherwise a default layout).
CaptureLayout DescribeCapture(const Reconstruction& reconstruction);

}  // namespace raycarve
