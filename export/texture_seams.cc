// MeasureTextureSeams of export/mesh_texture.h: how much the texture's colour steps across chart
// borders against inside the charts.
#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <utility>

#include "export/mesh_colouring.h"
#include "export/mesh_texture.h"

namespace raycarve {
namespace exporter {
namespace {

// The colour step across the edge (a, b) between triangle t and triangle u (see TextureSeams),
// in texels of `texture`; false where a sample falls outside it.
bool EdgeStep(const TriangleMesh& mesh, int t, int u, int a, int b, double* step) {
  const Eigen::Vector2d size(mesh.texture.cols, mesh.texture.rows);
  // Triangle's corners in texels: the edge's two, and its third; the inward unit normal.
  const auto corners = [&](int triangle, Eigen::Vector2d* pa, Eigen::Vector2d* pb, Eigen::Vector2d* inward) {
    Eigen::Vector2d third = Eigen::Vector2d::Zero();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d uv = mesh.corner_uvs[3 * triangle + k].cast<double>().cwiseProduct(size);
      const int vertex = mesh.triangles[triangle][k];
      if (vertex == a) {
        *pa = uv;
      } else if (vertex == b) {
        *pb = uv;
      } else {
        third = uv;
      }
    }
    const Eigen::Vector2d along = *pb - *pa;
    if (!(along.norm() > 1e-9)) return false;
    Eigen::Vector2d normal(-along.y(), along.x());
    normal.normalize();
    if (normal.dot(third - *pa) < 0.0) normal = -normal;
    *inward = normal;
    return true;
  };
  Eigen::Vector2d ta = Eigen::Vector2d::Zero(), tb = ta, tn = ta, ua = ta, ub = ta, un = ta;
  if (!corners(t, &ta, &tb, &tn) || !corners(u, &ua, &ub, &un)) return false;
  double sum = 0.0;
  for (const double f : {0.25, 0.5, 0.75}) {
    Eigen::Vector3f ct, cu;
    if (!SampleBilinear(mesh.texture, ta + f * (tb - ta) + tn, &ct) ||
        !SampleBilinear(mesh.texture, ua + f * (ub - ua) + un, &cu)) {
      return false;
    }
    sum += (ct - cu).norm() / std::sqrt(3.0);
  }
  *step = sum / 3.0;
  return true;
}

}  // namespace

TextureSeams MeasureTextureSeams(const TriangleMesh& mesh) {
  TextureSeams seams;
  if (!mesh.textured()) return seams;
  std::unordered_map<uint64_t, std::pair<int, int>> by_edge;  // the first two triangles
  by_edge.reserve(mesh.triangles.size() * 2);
  double seam_sum = 0.0, inner_sum = 0.0;
  for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.triangles[t][k], b = mesh.triangles[t][(k + 1) % 3];
      const uint64_t key = (static_cast<uint64_t>(std::min(a, b)) << 32) | static_cast<uint32_t>(std::max(a, b));
      auto [it, first] = by_edge.emplace(key, std::make_pair(t, -1));
      if (first || it->second.second >= 0) continue;
      it->second.second = t;
      const int u = it->second.first;
      // Same chart: the edge's corners have the same texture coordinates in both triangles.
      const auto uv = [&](int triangle, int vertex) {
        for (int c = 0; c < 3; ++c) {
          if (mesh.triangles[triangle][c] == vertex) return mesh.corner_uvs[3 * triangle + c];
        }
        return Eigen::Vector2f(-1.0f, -1.0f);
      };
      const bool inner = (uv(t, a) - uv(u, a)).norm() < 1e-7f && (uv(t, b) - uv(u, b)).norm() < 1e-7f;
      double step = 0.0;
      if (!EdgeStep(mesh, t, u, a, b, &step)) continue;
      if (inner) {
        ++seams.inner_edges;
        inner_sum += step;
      } else {
        ++seams.seam_edges;
        seam_sum += step;
      }
    }
  }
  if (seams.seam_edges > 0) seams.seam_step = seam_sum / seams.seam_edges;
  if (seams.inner_edges > 0) seams.inner_step = inner_sum / seams.inner_edges;
  return seams;
}

}  // namespace exporter
}  // namespace raycarve
