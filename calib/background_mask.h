#pragma once

#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace raycarve {

// Object masks for photos of an object on a plain backdrop (a studio set-up, the Middlebury
// sets), when the user has no mask files.
struct BackgroundOptions {
  enum class Mode {
    kNone,    // no backdrop: every pixel is used (natural scenes)
    kAuto,    // each photo's backdrop colour estimated from its border
    kColour,  // the backdrop colour given in `colour`
  };
  Mode mode = Mode::kNone;
  Eigen::Vector3d colour = Eigen::Vector3d::Zero();  // RGB 0-255, for kColour
  // A pixel farther than this from the backdrop colour (Euclidean RGB distance) is object.
  double tolerance = 30.0;

  bool IsValid(std::string* reason) const;
};

// "none", "auto" or "R,G,B"; throws InputError naming --background_colour otherwise.
BackgroundOptions::Mode ParseBackground(const std::string& text, Eigen::Vector3d* colour);

// The backdrop colour of a photo (CV_8UC3 RGB): the per-channel median of its border pixels
// (the outermost 2% of rows and columns). Returns false when the border is not one colour (fewer
// than 80% of its pixels within `tolerance` of the median), i.e. there is no plain backdrop.
bool EstimateBackdropColour(const cv::Mat& rgb, double tolerance, Eigen::Vector3d* colour);

// The object mask (CV_8UC1, 255 = object) of a photo on a backdrop of colour `backdrop`: pixels
// farther than `tolerance` from it, cleaned of specks (opening, 3x3) and of pinholes (closing,
// 5x5). Holes larger than that stay background, since objects can have real openings.
cv::Mat ObjectMaskFromBackdrop(const cv::Mat& rgb, const Eigen::Vector3d& backdrop, double tolerance);

}  // namespace raycarve
