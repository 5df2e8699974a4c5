#pragma once

#include <string>
#include <vector>

#include "calib/background_mask.h"
#include "calib/calibrated_view.h"
#include "calib/reconstruction.h"

namespace raycarve {

// The least share of an undistorted photo that must have a source pixel (ReadCalibratedViews
// refuses a camera whose distortion leaves less: it folds the image).
constexpr double kMinValidShare = 0.01;

struct ViewReaderOptions {
  // Skip registered images whose photo is missing (counted and logged) instead of failing.
  bool skip_missing_images = false;
  // Folder of object masks (non-zero = object), one per photo, named as COLMAP names them
  // (<photo name>.png) or exactly as the photo; empty: no masks.
  std::string mask_path;
  // Without mask files: masks computed from a plain backdrop (see background_mask.h).
  BackgroundOptions background;
  // The volume to carve, when known: automatic masks take the sparse points inside it as sure
  // object and the pixels whose rays miss it as backdrop. Empty: every sparse point, no cut.
  Eigen::AlignedBox3d volume;
  // Threads decoding and masking photos (0: one per core); the result is the same for any.
  int num_threads = 0;
  // Photos whose longer side exceeds this are scaled down to it (INTER_AREA; masks by nearest
  // neighbour), their cameras with them (RescaledCamera); <= 0: full size.
  int max_image_size = 0;
};

// What was found for one photo's mask.
struct PhotoMaskInfo {
  std::string name;    // the image's name in the model
  std::string source;  // "file", "backdrop", "colour" (the given backdrop colour) or "none"
  BackdropModel backdrop;   // for "backdrop" and for "none" under kAuto (found = false)
  ObjectMaskReport mask;    // for "backdrop"
  double object_share = 0.0;  // of the photo's pixels, for any source with a mask
};

struct ViewReaderSummary {
  int num_registered = 0;
  int num_loaded = 0;
  int masks_from_files = 0;
  int masks_from_backdrop = 0;
  int no_plain_backdrop = 0;  // kAuto found no one-coloured border: that view has no mask
  // kAuto: photos whose border held the object's colours (BackdropModel::object_colours), set
  // aside before the backdrop was described; and the mean share of their borders set aside.
  int object_on_border = 0;
  double object_border_share = 0.0;
  Eigen::Vector3d mean_backdrop = Eigen::Vector3d::Zero();  // over masks_from_backdrop views
  std::vector<std::string> missing;  // photo paths not found (only with skip_missing_images)
  std::vector<PhotoMaskInfo> photos;  // per loaded view, in view order
  int num_downscaled = 0;             // photos scaled down by max_image_size
  std::string Summary() const;
};

// Loads the photo of every registered image of `reconstruction` from `image_path` / image.name
// (and its mask from options.mask_path) and builds its CalibratedView (undistorted, in image-id
// order). Throws InputError naming the photo's path and image id when a photo is missing (unless
// skipped), cannot be decoded, or has the wrong size; naming the mask paths tried when a mask is
// missing, undecodable or of the wrong size; and when no view at all could be built.
std::vector<CalibratedView> ReadCalibratedViews(const Reconstruction& reconstruction,
                                                const std::string& image_path,
                                                const ViewReaderOptions& options,
                                                ViewReaderSummary* summary);

}  // namespace raycarve
