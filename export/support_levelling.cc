#include "export/support_levelling.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <glog/logging.h>

namespace raycarve {
namespace exporter {

std::string SupportLevelling::Summary() const {
  std::ostringstream text;
  text.precision(3);
  text << vertices << " vertices within " << band
       << " of the supporting plane levelled onto it (mean move " << mean_move << ")";
  if (undone > 0) text << ", " << undone << " moved back where that made the mesh fold";
  return text.str();
}

SupportLevelling LevelOntoSupport(const Ground& support, double voxel_size, double min_band,
                                  TriangleMesh* mesh) {
  CHECK(voxel_size > 0.0);
  CHECK(mesh->normals.size() == mesh->vertices.size());
  SupportLevelling levelling;
  levelling.band = std::max(2.0 * voxel_size, min_band);
  if (support.empty()) return levelling;
  const GroundMap map(support);
  const double min_cos = std::cos(kLevelledNormalDegrees / 180.0 * M_PI);
  double moved = 0.0;
  for (size_t i = 0; i < mesh->vertices.size(); ++i) {
    const Eigen::Vector3d vertex = mesh->vertices[i].cast<double>();
    const double height = map.Height(vertex);
    if (std::abs(height) >= levelling.band) continue;
    if (map.At(vertex) != GroundMap::Foot::kGround) continue;
    // Onto the plane; the underside of a thin top (a mat), facing down, to half a voxel under it
    // at least, so that the top levelled onto the plane stays above it. What faces sideways goes
    // onto the plane too: refinement's wrinkles tilt single normals of the top, which left where
    // they were would stand up as spikes through the levelled triangles around them; the foot of
    // a wall standing on the plane is on it already.
    const double facing = support.normal.dot(mesh->normals[i].cast<double>());
    const double target = facing <= -min_cos ? std::min(height, -0.5 * voxel_size) : 0.0;
    if (target == height) continue;
    // All the way within half the band (a voxel at two voxels), then less, to nothing at the band.
    const double share = std::min(1.0, 2.0 - 2.0 * std::abs(height) / levelling.band);
    mesh->vertices[i] = (vertex + share * (target - height) * support.normal).cast<float>();
    moved += share * std::abs(target - height);
    ++levelling.vertices;
  }
  if (levelling.vertices > 0) {
    levelling.mean_move = moved / static_cast<double>(levelling.vertices);
    ComputeVertexNormals(mesh);
  }
  return levelling;
}

}  // namespace exporter
}  // namespace raycarve
