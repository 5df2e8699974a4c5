#pragma once

#include <cstdint>
#include <limits>

namespace raycarve {

// Identifiers as COLMAP stores them in its binary model files.
using camera_t = uint32_t;
using image_t = uint32_t;
using point3D_t = uint64_t;
using point2D_t = uint32_t;

// COLMAP's marker for "this 2D point has no 3D point" (2^64 - 1; -1 in text files).
constexpr point3D_t kInvalidPoint3DId = std::numeric_limits<point3D_t>::max();

}  // namespace raycarve
