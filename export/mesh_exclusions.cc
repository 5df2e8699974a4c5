#include "export/mesh_exclusions.h"

#include <functional>
#include <limits>
#include <queue>
#include <utility>

#include <glog/logging.h>

#include "export/mesh_renderer.h"

namespace raycarve {
namespace exporter {

std::vector<uint8_t> GridWallVertices(const TriangleMesh& mesh, const VoxelGrid& grid) {
  // Smoothing rounds the wall's edges and refinement moves vertices up to a voxel along their
  // normals: 1.5 voxels holds the wall, not the surface a voxel and more inside it.
  const double reach = 1.5 * grid.voxel_size();
  const double min_cosine = 0.5;
  const Eigen::AlignedBox3d box = grid.Box();
  std::vector<uint8_t> on_wall(mesh.vertices.size(), 0);
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d p = mesh.vertices[i].cast<double>();
    const Eigen::Vector3d n = mesh.normals[i].cast<double>();
    for (int axis = 0; axis < 3 && on_wall[i] == 0; ++axis) {
      const bool near_min = p[axis] - box.min()[axis] <= reach && -n[axis] >= min_cosine;
      const bool near_max = box.max()[axis] - p[axis] <= reach && n[axis] >= min_cosine;
      on_wall[i] = near_min || near_max;
    }
  }
  return on_wall;
}

std::vector<uint8_t> UncoveredVertices(const TriangleMesh& mesh,
                                       const std::vector<CalibratedView>& views, int min_views) {
  std::vector<uint8_t> uncovered(mesh.vertices.size(), 0);
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d p = mesh.vertices[i].cast<double>();
    int frames = 0;
    for (const CalibratedView& view : views) {
      if (view.FramesPoint(p) && ++frames >= min_views) break;
    }
    uncovered[i] = frames < min_views;
  }
  return uncovered;
}

std::vector<uint8_t> UnseenVertices(const TriangleMesh& mesh, const std::vector<CalibratedView>& views,
                                    int min_views, double tolerance) {
  std::vector<int> seen(mesh.vertices.size(), 0);
  for (const CalibratedView& view : views) {
    const cv::Mat depths = RenderMeshDepth(mesh, view);
    for (size_t i = 0; i < mesh.vertices.size(); ++i) {
      if (seen[i] >= min_views) continue;
      const Eigen::Vector3d image = view.P * mesh.vertices[i].cast<double>().homogeneous();
      const double depth = image.z();
      if (!(depth > 0.0)) continue;
      const double col = std::floor(image.x() / depth), row = std::floor(image.y() / depth);
      if (!(col >= 0.0 && row >= 0.0 && col < view.width && row < view.height)) continue;
      const int c = static_cast<int>(col), r = static_cast<int>(row);
      if (view.valid.at<uint8_t>(r, c) == 0) continue;
      if (depth <= depths.at<float>(r, c) + tolerance) ++seen[i];
    }
  }
  std::vector<uint8_t> unseen(mesh.vertices.size(), 0);
  for (size_t i = 0; i < seen.size(); ++i) unseen[i] = seen[i] < min_views;
  return unseen;
}

int64_t KeepUnseenNearSeen(const TriangleMesh& mesh, const std::vector<uint8_t>& excluded,
                           double reach, std::vector<uint8_t>* unseen) {
  CHECK(unseen->size() == mesh.vertices.size() && excluded.size() == mesh.vertices.size());
  const std::vector<std::vector<int>> neighbours = VertexNeighbours(mesh);
  // Distances along the edges from the seen surface, through unseen vertices only (Dijkstra).
  std::vector<double> distance(mesh.vertices.size(), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (size_t i = 0; i < distance.size(); ++i) {
    if (!(*unseen)[i] && !excluded[i]) {
      distance[i] = 0.0;
      queue.push({0.0, static_cast<int>(i)});
    }
  }
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > distance[v]) continue;
    for (int w : neighbours[v]) {
      if (!(*unseen)[w] || excluded[w]) continue;
      const double through = d + (mesh.vertices[v] - mesh.vertices[w]).cast<double>().norm();
      if (through < distance[w] && through <= reach) {
        distance[w] = through;
        queue.push({through, w});
      }
    }
  }
  int64_t kept = 0;
  for (size_t i = 0; i < distance.size(); ++i) {
    if ((*unseen)[i] && distance[i] <= reach) {
      (*unseen)[i] = 0;
      ++kept;
    }
  }
  return kept;
}

std::vector<uint8_t> GroundFillVertices(const TriangleMesh& mesh, const Ground& ground,
                                        double voxel_size) {
  std::vector<uint8_t> fill(mesh.vertices.size(), 0);
  if (ground.empty()) return fill;
  const GroundMap map(ground);
  const Eigen::Vector3d up = ground.normal.normalized();
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3d p = mesh.vertices[i].cast<double>();
    const double height = map.Height(p);
    if (height >= -(ground.depth + 0.25 * voxel_size)) continue;
    const bool facing_up = i < mesh.normals.size() && mesh.normals[i].cast<double>().dot(up) >= 0.5;
    if (facing_up && height >= -(ground.depth + voxel_size)) continue;
    fill[i] = map.NearGround(p, 1.5 * voxel_size);
  }
  return fill;
}

}  // namespace exporter
}  // namespace raycarve
