#include "export/mesh_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glog/logging.h>

#include "export/mesh_colouring.h"

namespace raycarve {
namespace exporter {

namespace {

// Calls `pixel(triangle, row, col, a0, a1, a2)` for every pixel centre (COLMAP convention)
// inside a triangle's projection, triangle by triangle in the mesh's order: a_k is the centre's
// screen-space barycentric weight of corner k times that corner's inverse depth, so that their
// sum is the inverse depth there (1/z is linear in screen space) and a_k / sum the
// perspective-correct weights.
// Triangles with a vertex at or behind the camera plane are skipped; with `front_faces_only`,
// so are those whose winding faces away from the camera.
template <typename PixelFn>
void ForEachCoveredPixel(const TriangleMesh& mesh, const CalibratedView& view,
                         bool front_faces_only, PixelFn&& pixel) {
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
  for (size_t triangle = 0; triangle < mesh.triangles.size(); ++triangle) {
    const Eigen::Vector3i& t = mesh.triangles[triangle];
    const double iz0 = inverse_depths[t[0]], iz1 = inverse_depths[t[1]], iz2 = inverse_depths[t[2]];
    if (!(iz0 > 0.0 && iz1 > 0.0 && iz2 > 0.0)) continue;
    const Eigen::Vector2d& a = pixels[t[0]];
    const Eigen::Vector2d& b = pixels[t[1]];
    const Eigen::Vector2d& c = pixels[t[2]];
    const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (!(std::abs(area) > 1e-12)) continue;
    // Pixels run right and down as the camera's x and y, so a triangle whose outward side faces
    // the camera (its normal towards the camera, -z) winds clockwise on the screen: area < 0.
    // (Tested before the bounding box: about half the triangles face away.)
    if (front_faces_only && area > 0.0) continue;
    // Pixel centres (col + 0.5, row + 0.5) inside the triangle's bounding box.
    // (Clamped to the frame before they become ints: a vertex far off-screen, or nearly on the
    // camera plane, projects beyond int's range.)
    const auto bound = [](double value, int size) {
      return static_cast<int>(std::clamp(value, -1.0, static_cast<double>(size)));
    };
    const int col_min = std::max(0, bound(std::ceil(std::min({a.x(), b.x(), c.x()}) - 0.5), view.width));
    const int col_max = std::min(view.width - 1,
                                 bound(std::floor(std::max({a.x(), b.x(), c.x()}) - 0.5), view.width));
    if (col_min > col_max) continue;
    const int row_min = std::max(0, bound(std::ceil(std::min({a.y(), b.y(), c.y()}) - 0.5), view.height));
    const int row_max = std::min(view.height - 1,
                                 bound(std::floor(std::max({a.y(), b.y(), c.y()}) - 0.5), view.height));
    if (row_min > row_max) continue;
    const double inverse_area = 1.0 / area;
    // Barycentric weights of (x, y), screen space: w0 = e0 + x * dx0 + y * dy0, likewise w1;
    // w2 = 1 - w0 - w1.
    const double dx0 = (b.y() - c.y()) * inverse_area, dy0 = (c.x() - b.x()) * inverse_area;
    const double e0 = (b.x() * c.y() - b.y() * c.x()) * inverse_area;
    const double dx1 = (c.y() - a.y()) * inverse_area, dy1 = (a.x() - c.x()) * inverse_area;
    const double e1 = (c.x() * a.y() - c.y() * a.x()) * inverse_area;
    for (int row = row_min; row <= row_max; ++row) {
      const double y = row + 0.5;
      const double x0 = col_min + 0.5;
      double w0 = e0 + x0 * dx0 + y * dy0;
      double w1 = e1 + x0 * dx1 + y * dy1;
      for (int col = col_min; col <= col_max; ++col, w0 += dx0, w1 += dx1) {
        const double w2 = 1.0 - w0 - w1;
        // Edges shared by two triangles: a centre on the edge is taken by both (harmless).
        if (w0 < -1e-9 || w1 < -1e-9 || w2 < -1e-9) continue;
        pixel(triangle, row, col, w0 * iz0, w1 * iz1, w2 * iz2);
      }
    }
  }
}

// Draws `mesh` into `view` with a depth buffer `depth` (CV_32FC1, +inf where nothing is drawn);
// `image` and `silhouette`, when not null, get the colours and the covered pixels.
void Rasterise(const TriangleMesh& mesh, const CalibratedView& view, bool front_faces_only,
               cv::Mat* depth, cv::Mat* image, cv::Mat* silhouette) {
  *depth = cv::Mat(view.height, view.width, CV_32FC1,
                   cv::Scalar(std::numeric_limits<float>::infinity()));
  if (image != nullptr) *image = cv::Mat(view.height, view.width, CV_8UC3, cv::Scalar::all(0));
  if (silhouette != nullptr) *silhouette = cv::Mat(view.height, view.width, CV_8UC1, cv::Scalar(0));
  const bool coloured = image != nullptr && mesh.colours.size() == mesh.vertices.size();
  const bool textured = image != nullptr && mesh.textured();
  ForEachCoveredPixel(mesh, view, front_faces_only,
                      [&](size_t triangle, int row, int col, double a0, double a1, double a2) {
    const double inverse_z = a0 + a1 + a2;
    const float z = static_cast<float>(1.0 / inverse_z);
    float& nearest = depth->at<float>(row, col);
    if (!(z < nearest)) return;
    nearest = z;
    if (silhouette != nullptr) silhouette->at<uint8_t>(row, col) = 255;
    if (image == nullptr) return;
    cv::Vec3b& colour = image->at<cv::Vec3b>(row, col);
    if (textured) {
      const double p0 = a0 / inverse_z, p1 = a1 / inverse_z, p2 = a2 / inverse_z;
      const Eigen::Vector2f* uv = &mesh.corner_uvs[3 * triangle];
      const Eigen::Vector2d at = (p0 * uv[0].cast<double>() + p1 * uv[1].cast<double>() +
                                  p2 * uv[2].cast<double>())
                                     .cwiseProduct(Eigen::Vector2d(mesh.texture.cols,
                                                                   mesh.texture.rows));
      // Inside the atlas's pixel centres (a corner's coordinate can sit on a chart's edge).
      const Eigen::Vector2d clamped(std::clamp(at.x(), 0.5, mesh.texture.cols - 0.5),
                                    std::clamp(at.y(), 0.5, mesh.texture.rows - 0.5));
      Eigen::Vector3f sample;
      if (SampleBilinear(mesh.texture, clamped, &sample)) {
        for (int k = 0; k < 3; ++k) {
          colour[k] = static_cast<uint8_t>(std::clamp(std::lround(sample[k]), 0L, 255L));
        }
        return;
      }
    }
    if (!coloured) {
      colour = cv::Vec3b(128, 128, 128);
      return;
    }
    const Eigen::Vector3i& t = mesh.triangles[triangle];
    const double p0 = a0 / inverse_z, p1 = a1 / inverse_z, p2 = a2 / inverse_z;
    for (int k = 0; k < 3; ++k) {
      const double value = p0 * mesh.colours[t[0]][k] + p1 * mesh.colours[t[1]][k] +
                           p2 * mesh.colours[t[2]][k];
      colour[k] = static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
    }
  });
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

void DrawMeshParts(const TriangleMesh& mesh, const std::vector<int>& triangle_part, int num_parts,
                   const CalibratedView& view, cv::Mat* count, cv::Mat* last_part,
                   std::vector<int64_t>* covered) {
  CHECK_EQ(triangle_part.size(), mesh.triangles.size());
  *count = cv::Mat(view.height, view.width, CV_8UC1, cv::Scalar(0));
  *last_part = cv::Mat(view.height, view.width, CV_32SC1, cv::Scalar(-1));
  covered->assign(num_parts, 0);
  int previous = -1;
  ForEachCoveredPixel(mesh, view, /*front_faces_only=*/true,
                      [&](size_t triangle, int row, int col, double, double, double) {
    const int part = triangle_part[triangle];
    CHECK(part >= previous && part < num_parts) << "the triangles must be grouped by part";
    previous = part;
    int& last = last_part->at<int>(row, col);
    if (last == part) return;
    last = part;
    uint8_t& n = count->at<uint8_t>(row, col);
    if (n < 255) ++n;
    ++(*covered)[part];
  });
}

}  // namespace exporter
}  // namespace raycarve
