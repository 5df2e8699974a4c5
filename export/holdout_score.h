#pragma once

#include <string>

#include <opencv2/core.hpp>

#include "calib/calibrated_view.h"
#include "export/point_renderer.h"

namespace raycarve {
namespace exporter {

// How well a rendering of the model reproduces a photo the model was not made from.
struct HoldoutScore {
  double psnr = 0.0;            // dB over the scored pixels (RGB, peak 255)
  int scored_pixels = 0;        // the union of the rendered silhouette and the photo's object
                                // mask when it has one; otherwise every pixel with photo data
  double silhouette_iou = -1.0; // rendered silhouette vs the photo's mask; -1 without a mask
};

// Scores `rendering` against `view` (its undistorted photo, valid pixels and mask).
HoldoutScore ScoreRendering(const Rendering& rendering, const CalibratedView& view);

// photo | render | error (absolute difference, amplified 4x), side by side, RGB.
cv::Mat SideBySide(const Rendering& rendering, const CalibratedView& view);

}  // namespace exporter
}  // namespace raycarve
