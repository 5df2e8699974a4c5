#include "export/mesh_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace raycarve {
namespace exporter {

Rendering RenderMesh(const TriangleMesh& mesh, const CalibratedView& view) {
  Rendering rendering;
  rendering.image = cv::Mat(view.height, view.width, CV_8UC3, cv::Scalar::all(0));
  rendering.silhouette = cv::Mat(view.height, view.width, CV_8UC1, cv::Scalar(0));
  rendering.depth = cv::Mat(view.height, view.width, CV_32FC1,
                            cv::Scalar(std::numeric_limits<float>::infinity()));
  const size_t n = mesh.vertices.size();
  std::vector<Eigen::Vector2d> pixels(n);
  std::vector<double> depths(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d world = mesh.vertices[i].cast<double>();
    depths[i] = view.Depth(world);
    pixels[i] = depths[i] > 0.0 ? view.Project(world) : Eigen::Vector2d::Zero();
  }
  const bool coloured = mesh.colours.size() == n;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const double z0 = depths[t[0]], z1 = depths[t[1]], z2 = depths[t[2]];
    if (!(z0 > 0.0 && z1 > 0.0 && z2 > 0.0)) continue;
    const Eigen::Vector2d& a = pixels[t[0]];
    const Eigen::Vector2d& b = pixels[t[1]];
    const Eigen::Vector2d& c = pixels[t[2]];
    const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (!(std::abs(area) > 1e-12)) continue;
    // Pixel centres (col + 0.5, row + 0.5) inside the triangle's bounding box.
    const int col_min = std::max(0, static_cast<int>(std::ceil(std::min({a.x(), b.x(), c.x()}) - 0.5)));
    const int col_max = std::min(view.width - 1,
                                 static_cast<int>(std::floor(std::max({a.x(), b.x(), c.x()}) - 0.5)));
    const int row_min = std::max(0, static_cast<int>(std::ceil(std::min({a.y(), b.y(), c.y()}) - 0.5)));
    const int row_max = std::min(view.height - 1,
                                 static_cast<int>(std::floor(std::max({a.y(), b.y(), c.y()}) - 0.5)));
    if (col_min > col_max || row_min > row_max) continue;
    const double inverse_area = 1.0 / area;
    for (int row = row_min; row <= row_max; ++row) {
      const double y = row + 0.5;
      float* depth_row = rendering.depth.ptr<float>(row);
      cv::Vec3b* colour_row = rendering.image.ptr<cv::Vec3b>(row);
      uint8_t* covered_row = rendering.silhouette.ptr<uint8_t>(row);
      for (int col = col_min; col <= col_max; ++col) {
        const double x = col + 0.5;
        // Barycentric weights of the pixel centre (screen space).
        const double w0 = ((b.x() - x) * (c.y() - y) - (b.y() - y) * (c.x() - x)) * inverse_area;
        const double w1 = ((c.x() - x) * (a.y() - y) - (c.y() - y) * (a.x() - x)) * inverse_area;
        const double w2 = 1.0 - w0 - w1;
        // Edges shared by two triangles: a centre on the edge is taken by both (harmless).
        if (w0 < -1e-9 || w1 < -1e-9 || w2 < -1e-9) continue;
        // Perspective-correct: 1/z is linear in screen space.
        const double inverse_z = w0 / z0 + w1 / z1 + w2 / z2;
        const float z = static_cast<float>(1.0 / inverse_z);
        if (!(z < depth_row[col])) continue;
        depth_row[col] = z;
        covered_row[col] = 255;
        if (coloured) {
          const double p0 = w0 / z0 / inverse_z, p1 = w1 / z1 / inverse_z, p2 = w2 / z2 / inverse_z;
          cv::Vec3b colour;
          for (int k = 0; k < 3; ++k) {
            const double value = p0 * mesh.colours[t[0]][k] + p1 * mesh.colours[t[1]][k] +
                                 p2 * mesh.colours[t[2]][k];
            colour[k] = static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
          }
          colour_row[col] = colour;
        } else {
          colour_row[col] = cv::Vec3b(128, 128, 128);
        }
      }
    }
  }
  return rendering;
}

}  // namespace exporter
}  // namespace raycarve
