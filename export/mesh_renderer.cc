#include "export/mesh_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace raycarve {
namespace exporter {

namespace {

// Draws `mesh` into `view` with a depth buffer `depth` (CV_32FC1, +inf where nothing is drawn);
// `image` and `silhouette`, when not null, get the colours and the covered pixels.
void Rasterise(const TriangleMesh& mesh, const CalibratedView& view, bool front_faces_only,
               cv::Mat* depth, cv::Mat* image, cv::Mat* silhouette) {
  *depth = cv::Mat(view.height, view.width, CV_32FC1,
                   cv::Scalar(std::numeric_limits<float>::infinity()));
  if (image != nullptr) *image = cv::Mat(view.height, view.width, CV_8UC3, cv::Scalar::all(0));
  if (silhouette != nullptr) *silhouette = cv::Mat(view.height, view.width, CV_8UC1, cv::Scalar(0));
  const size_t n = mesh.vertices.size();
  // Per vertex: its pixel and the inverse of its depth (P's last row is the camera's z, as K's
  // last row is (0, 0, 1)); 0 at or behind the camera plane.
  std::vector<Eigen::Vector2d> pixels(n);
  std::vector<double> inverse_depths(n);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d image = view.P * mesh.vertices[i].cast<double>().homogeneous();
    const double z = image.z();
    inverse_depths[i] = z > 0.0 ? 1.0 / z : 0.0;
    pixels[i] = z > 0.0 ? Eigen::Vector2d(image.head<2>() / z) : Eigen::Vector2d::Zero();
  }
  const bool coloured = image != nullptr && mesh.colours.size() == n;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const double iz0 = inverse_depths[t[0]], iz1 = inverse_depths[t[1]], iz2 = inverse_depths[t[2]];
    if (!(iz0 > 0.0 && iz1 > 0.0 && iz2 > 0.0)) continue;
    const Eigen::Vector2d& a = pixels[t[0]];
    const Eigen::Vector2d& b = pixels[t[1]];
    const Eigen::Vector2d& c = pixels[t[2]];
    // Pixel centres (col + 0.5, row + 0.5) inside the triangle's bounding box.
    const int col_min = std::max(0, static_cast<int>(std::ceil(std::min({a.x(), b.x(), c.x()}) - 0.5)));
    const int col_max = std::min(view.width - 1,
                                 static_cast<int>(std::floor(std::max({a.x(), b.x(), c.x()}) - 0.5)));
    if (col_min > col_max) continue;
    const int row_min = std::max(0, static_cast<int>(std::ceil(std::min({a.y(), b.y(), c.y()}) - 0.5)));
    const int row_max = std::min(view.height - 1,
                                 static_cast<int>(std::floor(std::max({a.y(), b.y(), c.y()}) - 0.5)));
    if (row_min > row_max) continue;
    const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (!(std::abs(area) > 1e-12)) continue;
    // Pixels run right and down as the camera's x and y, so a triangle whose outward side faces
    // the camera (its normal towards the camera, -z) winds clockwise on the screen: area < 0.
    if (front_faces_only && area > 0.0) continue;
    const double inverse_area = 1.0 / area;
    // Barycentric weights of (x, y), screen space: w0 = e0 + x * dx0 + y * dy0, likewise w1;
    // w2 = 1 - w0 - w1.
    const double dx0 = (b.y() - c.y()) * inverse_area, dy0 = (c.x() - b.x()) * inverse_area;
    const double e0 = (b.x() * c.y() - b.y() * c.x()) * inverse_area;
    const double dx1 = (c.y() - a.y()) * inverse_area, dy1 = (a.x() - c.x()) * inverse_area;
    const double e1 = (c.x() * a.y() - c.y() * a.x()) * inverse_area;
    for (int row = row_min; row <= row_max; ++row) {
      const double y = row + 0.5;
      float* depth_row = depth->ptr<float>(row);
      cv::Vec3b* colour_row = image != nullptr ? image->ptr<cv::Vec3b>(row) : nullptr;
      uint8_t* covered_row = silhouette != nullptr ? silhouette->ptr<uint8_t>(row) : nullptr;
      const double x0 = col_min + 0.5;
      double w0 = e0 + x0 * dx0 + y * dy0;
      double w1 = e1 + x0 * dx1 + y * dy1;
      for (int col = col_min; col <= col_max; ++col, w0 += dx0, w1 += dx1) {
        const double w2 = 1.0 - w0 - w1;
        // Edges shared by two triangles: a centre on the edge is taken by both (harmless).
        if (w0 < -1e-9 || w1 < -1e-9 || w2 < -1e-9) continue;
        // Perspective-correct: 1/z is linear in screen space.
        const double inverse_z = w0 * iz0 + w1 * iz1 + w2 * iz2;
        const float z = static_cast<float>(1.0 / inverse_z);
        if (!(z < depth_row[col])) continue;
        depth_row[col] = z;
        if (covered_row != nullptr) covered_row[col] = 255;
        if (colour_row == nullptr) continue;
        if (coloured) {
          const double p0 = w0 * iz0 / inverse_z, p1 = w1 * iz1 / inverse_z, p2 = w2 * iz2 / inverse_z;
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
}

}  // namespace

Rendering RenderMesh(const TriangleMesh& mesh, const CalibratedView& view, bool front_faces_only) {
  Rendering rendering;
  Rasterise(mesh, view, front_faces_only, &rendering.depth, &rendering.image, &rendering.silhouette);
  return rendering;
}

cv::Mat RenderMeshDepth(const TriangleMesh& mesh, const CalibratedView& view, bool front_faces_only) {
  cv::Mat depth;
  Rasterise(mesh, view, front_faces_only, &depth, nullptr, nullptr);
  return depth;
}

}  // namespace exporter
}  // namespace raycarve
