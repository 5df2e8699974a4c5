#pragma once
// Which way is up in the world, from how the photos were held: people hold a camera level, so
// the photos' up (their cameras' -y axes) points up in the world on average (as COLMAP's own
// gravity estimate from image orientations assumes). Photos turned a quarter (portrait among
// landscape) or upside down are turned back first.

#include <vector>

#include <Eigen/Core>

#include "calib/rigid3d.h"

namespace raycarve {

// The photos say where up is when their turned-back ups agree at least this much (the length of
// their mean: cameras held every way give about 0.7 once each is turned towards the mean, so the
// second test, how many were held the same way, is what rules those out)...
constexpr double kMinPhotosUpAgreement = 0.3;
// ...and at least this share of them were held the same way (landscape, or one portrait turn).
constexpr double kMinPhotosHeldAlike = 0.5;

struct PhotosUp {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  // unit; +z where the photos cancel out
  // The length of the mean of the photos' up axes once turned back (1: all the same; a ring of
  // cameras looking down at 45 degrees: 0.71).
  double agreement = 0.0;
  int photos = 0;
  int held_alike = 0;  // photos held the most common way (the side of the frame that is up)
  int turned = 0;      // photos whose up is another side of the frame than the top
  bool Known() const;
};

// The photos' up from their poses: for each side of the frame (top, bottom, right, left) the mean
// over the photos of its direction in the world, the longest of the four as a start; then, twice,
// each photo's up taken as whichever of its frame's sides is nearest to the mean, and the mean
// taken again.
PhotosUp EstimatePhotosUp(const std::vector<Rigid3d>& cams_from_world);

}  // namespace raycarve
