#pragma once
// Internal to calib/: the verdicts of FindPixelsOnSurface's masks (calib/surface_pixels.cc) and
// the plain regions it judges by their rims.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "calib/distant_pixels.h"

namespace raycarve {

// The verdicts in DistantPixels::masks.
constexpr uint8_t kDistantJudged = 255;
constexpr uint8_t kGrown = 200;
constexpr uint8_t kUndecided = 128;
constexpr uint8_t kNearer = 64;

// The plain regions (connected pixels whose patch is not textured) whose rim is mostly found
// distant: the inside of a patch of sky whose edges move as the sky does. Marks them kGrown in
// `mask` (which holds the judged pixels' verdicts), counts their pixels in *grown and returns the
// pixels (COLMAP coordinates) of their rays, every `stride` pixels. A region holding one of
// `seen` (the photo's own pixels of sparse points inside the volume) is never distant: a plain
// object that runs into a sky of its colour without an edge has points where it has detail.
// The photo is given reduced: its grey levels (CV_32F), valid pixels, the smallest standard
// deviation of a textured patch, and the reduction `factor` (seen's pixels are full size).
std::vector<Eigen::Vector2d> GrowIntoPlainRegions(const cv::Mat& grey, const cv::Mat& valid,
                                                  double texture, int factor,
                                                  const DistantOptions& options,
                                                  const std::vector<Eigen::Vector2d>& seen,
                                                  cv::Mat* mask, int64_t* grown);

}  // namespace raycarve
