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
  bool applied = false;  // whether the photos were corrected (ColourCalibrationMode)
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

// When the photos are corrected:
//  - kOff: never; kOn: always (when some point is seen by enough photos);
//  - kAuto (the default): when the correction at least halves the sparse points' colour spread
//    across photos (ColourCalibrationPays), i.e. when different exposures or white balances are
//    most of what the photos disagree on. Where they are not, a correction fitted to the points'
//    remaining disagreement (texture edges, view-dependent shading, the points' own errors)
//    shifts the photos' colours for nothing: on the Middlebury sets (lit alike, spread 6.0-9.8
//    RGB, reduced to 0.69-0.94 of that) it lowered the held-out PSNR by 0.04-0.15 dB; on the
//    generated scene with exposures varying by 15% and 30% (spread 25.8 and 46 RGB, reduced to
//    0.30 and 0.19) it raised it by 0.4 and 1.3 dB.
enum class ColourCalibrationMode { kOff, kAuto, kOn };
constexpr double kColourCalibrationPays = 0.5;
bool ColourCalibrationPays(const ColourCalibration& calibration);
// "auto", "1" / "true" (kOn) or "0" / "false" (kOff); false for anything else.
bool ColourCalibrationModeFromString(const std::string& text, ColourCalibrationMode* mode);

// Applies (c - o) / g per channel to every view's image, rounded and clamped to 0-255.
void ApplyColourCalibration(const ColourCalibration& calibration, std::vector<CalibratedView>* views);

}  // namespace raycarve
