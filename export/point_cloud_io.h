#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "export/ply_reader.h"

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

// Reads a PLY point cloud (COLMAP's fused.ply, raycarve's own, or any PLY with x y z and
// optionally normals and colours; faces are ignored) through ReadPly. Missing normals and
// colours are zero. Throws InputError naming the path and the field when the file is missing or
// malformed.
std::vector<ColouredPoint> ReadPointCloudPly(const std::string& path);

}  // namespace exporter
}  // namespace raycarve
