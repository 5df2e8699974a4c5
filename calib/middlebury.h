#pragma once

#include <functional>
#include <istream>
#include <string>

#include <Eigen/Core>

#include "calib/reconstruction.h"

namespace raycarve {

// Import of Middlebury multi-view calibration files (`*_par.txt`) as a COLMAP model.
//
// Format: the number of images, then one line per image
//   name k11 k12 k13 k21 k22 k23 k31 k32 k33 r11 r12 r13 r21 r22 r23 r31 r32 r33 t1 t2 t3
// with P = K [R | t] mapping world to image, origin top-left. Each image becomes a PINHOLE camera
// (fx = k11, fy = k22, principal point (k13, k23) + principal_point_offset) with
// cam_from_world = (R, t); images with identical intrinsics and size share a camera. The model
// has no 3D points.
// How far (largest entry of |R R^T - I|) a rotation read from a file may be from orthonormal:
// the files print it to about 7 significant digits.
constexpr double kRotationTolerance = 1e-4;

struct MiddleburyImportOptions {
  // Added to (k13, k23) to reach COLMAP's convention. 0.5 reads the file as indexing pixel
  // centres at integers (the usual convention for such K); 0 copies K literally.
  double principal_point_offset = 0.5;

  bool IsValid(std::string* reason) const;
};

// `image_size(name)` returns (width, height) of the named photo. Throws InputError naming
// `source`, the line and the field on: a bad or missing count, a short line, a malformed number,
// non-zero skew or k31/k32, k33 != 1, non-positive focal lengths, R not a rotation (orthonormal
// with determinant +1 within kRotationTolerance; R is then replaced by the nearest rotation), fewer or more lines than the count, duplicate names.
Reconstruction ReadMiddleburyParameters(
    std::istream& stream,
    const std::string& source,
    const std::function<Eigen::Vector2i(const std::string& name)>& image_size,
    const MiddleburyImportOptions& options);

// Path form: reads `par_path` and takes each image's size from its photo in `image_path` (missing
// or undecodable photos throw InputError naming the path).
Reconstruction ImportMiddlebury(const std::string& par_path,
                                const std::string& image_path,
                                const MiddleburyImportOptions& options);

}  // namespace raycarve
