#include "export/support_levelling.h"

#include <cmath>
#include <sstream>

#include <glog/logging.h>

namespace raycarve {
namespace exporter {

std::string SupportLevelling::Summary() const {
  std::ostringstream text;
  text.precision(3);
  text << vertices << " vertices facing up or down within " << band
       << " of the supporting plane levelled onto it (mean move " << mean_move << ")";
  if (undone > 0) text << ", " << undone << " moved back where that made the mesh fold";
  return text.str();
}

SupportLevelling LevelOntoSupport(const Ground& support, double voxel_size, TriangleMesh* mesh) {
  CHECK(voxel_size > 0.0);
  CHECK(mesh->normals.size() == mesh->vertices.size());
  SupportLevelling levelling;
  levelling.band = 2.0 * voxel_size;
  if (support.empty()) return levelling;
  const GroundMap map(support);
  const double min_cos = std::cos(kLevelledNormalDegrees / 180.0 * M_PI);
  double moved = 0.0;
  for (size_t i = 0; i < mesh->vertices.size(); ++i) {
    const Eigen::Vector3d vertex = mesh->vertices[i].cast<double>();
    const double height = map.Height(vertex);
    if (std::abs(height) >= levelling.band) continue;
    const double facing = support.normal.dot(mesh->normals[i].cast<double>());
    // Facing up: onto the plane. Facing down (the underside of a thin top, a mat): to half a
    // voxel under it at least, so that the top levelled onto the plane stays above it.
    double target;
    if (facing >= min_cos) {
      target = 0.0;
    } else if (facing <= -min_cos) {
      target = std::min(height, -0.5 * voxel_size);
    } else {
      continue;
    }
    if (target == height || map.At(vertex) != GroundMap::Foot::kGround) continue;
    // All the way within a voxel, then less, to nothing at two.
    const double share = std::min(1.0, 2.0 - std::abs(height) / voxel_size);
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
