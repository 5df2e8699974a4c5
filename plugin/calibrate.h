#pragma once

#include <string>
#include <vector>

#include "calib/bounds.h"
#include "calib/calibrated_view.h"
#include "calib/reconstruction.h"

namespace raycarve {

// What `raycarve calibrate` checks per view: the model's sparse points reprojected through the
// view's 3x4 projection against their observations (moved into the view's undistorted pixels),
// and where the volume's box lands.
struct ViewCheck {
  image_t image_id = 0;
  std::string name;
  int num_observations = 0;  // observations with a 3D point in front of the camera
  int num_behind = 0;        // observations whose 3D point is behind the camera
  double mean_error = 0.0;   // pixels
  double median_error = 0.0;
  double max_error = 0.0;
  int box_corners_in_image = 0;  // of the 8 corners of the bounds
  bool box_in_front = true;      // all 8 corners in front of the camera
  double valid_fraction = 1.0;   // share of undistorted pixels that hold photo data
};

struct CalibrationReport {
  Bounds bounds;
  std::vector<ViewCheck> views;
  int num_observations = 0;
  double mean_error = 0.0;  // pixels, over all observations
  double max_error = 0.0;

  std::string Table() const;  // one line per view and a total
  std::string Json(const std::string& model_path,
                   const std::string& image_path,
                   const std::vector<CalibratedView>& calibrated) const;
};

// Checks `views` (built from `reconstruction`) against the sparse points and `bounds`.
CalibrationReport CalibrateProject(const Reconstruction& reconstruction,
                                   const std::vector<CalibratedView>& views,
                                   const Bounds& bounds);

}  // namespace raycarve
