#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/calibrated_view.h"
#include "calib/reconstruction.h"

namespace raycarve {

// Photos of one object differ in exposure and white balance. Each sparse 3D point is one surface
// colour a_j seen in several photos; photo i shows it as g_i * a_j + o_i per channel (a gain and
// an offset per photo and channel). The gains, offsets and point colours are estimated together
// by robust least squares (Ceres, Huber loss), with a weak prior pulling every photo towards no
// change (g = 1, o = 0), which also fixes the common scale and offset the data cannot tell.
struct ColourCalibrationOptions {
  // Huber scale of the colour residuals, RGB units.
  double loss_scale = 10.0;
  // Weight of the prior per photo, relative to one observation residual (gain in units of 1,
  // offset in units of 255).
  double prior_weight = 1.0;
  // Points seen (inside the photo data, and on the object where there is a mask) by fewer
  // photos than this are not used.
  int min_track_length = 3;
};

struct ColourCorrection {
  image_t image_id = 0;
  std::string name;
  Eigen::Vector3d gain = Eigen::Vector3d::Ones();
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  int observations = 0;
};

struct ColourCalibration {
  std::vector<ColourCorrection> corrections;  // one per view, in view order
  int points_used = 0;
  int observations_used = 0;
  // Mean over the used points of the RMS distance (RGB) of their observations to their mean:
  // how much the photos disagree on the sparse points, before and after the correction.
  double spread_before = 0.0;
  double spread_after = 0.0;
  std::string Summary() const;
};

// Estimates the corrections from the colours at which each view shows the model's 3D points
// (projected with the view's P into its undistorted image). Views are matched to images by
// image_id. Returns identity corrections (and points_used 0) when no point is seen by
// min_track_length views.
ColourCalibration EstimateColourCalibration(const Reconstruction& reconstruction,
                                            const std::vector<CalibratedView>& views,
                                            const ColourCalibrationOptions& options = {});

// Applies (c - o) / g per channel to every view's image, rounded and clamped to 0-255.
void ApplyColourCalibration(const ColourCalibration& calibration, std::vector<CalibratedView>* views);

}  // namespace raycarve
