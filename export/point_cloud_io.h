#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace raycarve {
namespace exporter {

// A coloured point with a normal, as COLMAP's fused.ply stores it.
struct ColouredPoint {
  Eigen::Vector3f xyz = Eigen::Vector3f::Zero();
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();  // zero when unknown
  Eigen::Matrix<uint8_t, 3, 1> rgb = Eigen::Matrix<uint8_t, 3, 1>::Zero();
};

// An RGB colour (0-255, any real values) rounded and clamped to bytes.
inline Eigen::Matrix<uint8_t, 3, 1> ToRgb(const Eigen::Vector3f& colour) {
  Eigen::Matrix<uint8_t, 3, 1> rgb;
  for (int k = 0; k < 3; ++k) {
    rgb[k] = static_cast<uint8_t>(std::clamp(std::lround(colour[k]), 0L, 255L));
  }
  return rgb;
}

// Writes a binary little-endian PLY through PCL, with per-vertex x y z, nx ny nz and
// red green blue (uchar), so that COLMAP, MeshLab, CloudCompare and Open3D open it. Written to a
// temporary name and renamed; throws InputError naming the path on failure.
void WritePointCloudPly(const std::vector<ColouredPoint>& points, const std::string& path);

// Checks a PLY file's header against the file before any reader sizes a buffer from it: "ply",
// a known format, elements whose counts fit in the bytes the file holds (binary: each record's
// fixed-size properties, lists counted as empty; ASCII: two characters per value), a vertex
// element with x, y and z, and no obj_info grid (num_cols x num_rows) larger than the vertex
// count. Returns the vertex count. Throws InputError naming the path and the field otherwise.
uint64_t CheckPlyHeader(const std::string& path);

// Reads a PLY point cloud (COLMAP's fused.ply, raycarve's own, or any PLY with x y z and
// optionally normals and colours) through PCL. Throws InputError naming the path when the file
// is missing or PCL cannot parse it.
std::vector<ColouredPoint> ReadPointCloudPly(const std::string& path);

}  // namespace exporter
}  // namespace raycarve
