#include "export/preview.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "calib/photos_up.h"
#include "export/mesh_renderer.h"

namespace raycarve {
namespace exporter {
namespace {

// A pinhole camera at `target` + distance * `direction` looking at `target`, with `up` (any
// vector not along `direction`) up in the image, a horizontal field of view of `fov_degrees`.
CalibratedView ViewFrom(const Eigen::Vector3d& target, double distance,
                        const Eigen::Vector3d& direction, const Eigen::Vector3d& up, int width,
                        int height, double fov_degrees) {
  CalibratedView view;
  view.width = width;
  view.height = height;
  const double focal = 0.5 * width / std::tan(0.5 * fov_degrees * M_PI / 180.0);
  view.K << focal, 0.0, 0.5 * width, 0.0, focal, 0.5 * height, 0.0, 0.0, 1.0;
  view.centre = target + distance * direction.normalized();
  const Eigen::Vector3d z = (target - view.centre).normalized();  // optical axis
  const Eigen::Vector3d x = (-up).cross(z).normalized();  // image right (y = -up: image down)
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d rotation;
  rotation << x.transpose(), y.transpose(), z.transpose();
  view.cam_from_world.rotation = Eigen::Quaterniond(rotation);
  view.cam_from_world.translation = -rotation * view.centre;
  view.P.leftCols<3>() = view.K * rotation;
  view.P.col(3) = view.K * view.cam_from_world.translation;
  return view;
}

}  // namespace

Eigen::Vector3d UpOfPhotos(const std::vector<CalibratedView>& views) {
  std::vector<Rigid3d> poses;
  for (const CalibratedView& view : views) poses.push_back(view.cam_from_world);
  return EstimatePhotosUp(poses).up;
}

std::vector<CalibratedView> ViewsFromOutside(const TriangleMesh& mesh,
                                             const std::vector<CalibratedView>& views, int count,
                                             int width, int height) {
  std::vector<CalibratedView> outside;
  if (mesh.vertices.empty() || views.empty() || count < 1) return outside;
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3f& v : mesh.vertices) box.extend(v.cast<double>());
  const Eigen::Vector3d target = box.center();
  const Eigen::Vector3d up = UpOfPhotos(views);
  std::vector<Eigen::Vector3d> seen_from;
  for (const CalibratedView& view : views) seen_from.push_back((view.centre - target).normalized());
  // Directions around the model: above, below, and eight around the horizon and 45 degrees up;
  // the `count` farthest (in angle) from every photo's, each next one also far from those taken.
  Eigen::Vector3d side = up.unitOrthogonal();
  const Eigen::Vector3d side2 = up.cross(side);
  std::vector<Eigen::Vector3d> candidates = {up, -up};
  for (int k = 0; k < 8; ++k) {
    const double angle = k * M_PI / 4.0;
    const Eigen::Vector3d around = std::cos(angle) * side + std::sin(angle) * side2;
    candidates.push_back(around);
    candidates.push_back((around + up).normalized());
  }
  const double fov = 40.0;
  const double radius = 0.5 * box.diagonal().norm();
  // The whole bounding sphere within the narrower of the two fields of view.
  const double half_across = 0.5 * fov * M_PI / 180.0;
  const double half_up = std::atan(std::tan(half_across) * height / std::max(1, width));
  const double distance = radius / std::sin(std::min(half_across, half_up));
  for (int taken = 0; taken < count; ++taken) {
    double best = -1.0;
    size_t best_index = 0;
    for (size_t c = 0; c < candidates.size(); ++c) {
      double nearest = M_PI;
      for (const Eigen::Vector3d& d : seen_from) {
        nearest = std::min(nearest, std::acos(std::clamp(d.dot(candidates[c]), -1.0, 1.0)));
      }
      if (nearest > best) {
        best = nearest;
        best_index = c;
      }
    }
    const Eigen::Vector3d direction = candidates[best_index];
    // Looking along up (from above or below), the image's up is the photos' mean direction.
    Eigen::Vector3d image_up = up;
    if (std::abs(direction.dot(up)) > 0.99) {
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (const Eigen::Vector3d& d : seen_from) mean += d - d.dot(up) * up;
      image_up = mean.norm() > 1e-6 ? Eigen::Vector3d(-mean.normalized()) : side;
    }
    outside.push_back(ViewFrom(target, distance, direction, image_up, width, height, fov));
    seen_from.push_back(direction);
  }
  return outside;
}

cv::Mat PreviewImage(const TriangleMesh& mesh, const std::vector<CalibratedView>& views, int count,
                     int max_width) {
  const int n = static_cast<int>(views.size());
  if (n == 0 || count < 1) return cv::Mat();
  const int rows = std::min(count, n);
  std::vector<cv::Mat> lines;
  int width = 0;
  for (int r = 0; r < rows; ++r) {
    // Evenly spread: the first, the last and between (one: the middle).
    const int index = rows == 1 ? n / 2 : static_cast<int>(static_cast<int64_t>(r) * (n - 1) / (rows - 1));
    const CalibratedView& view = views[index];
    cv::Mat pair;
    cv::hconcat(view.image, RenderMesh(mesh, view, /*front_faces_only=*/false).image, pair);
    const double scale = std::min(1.0, static_cast<double>(max_width) / pair.cols);
    if (scale < 1.0) cv::resize(pair, pair, cv::Size(), scale, scale, cv::INTER_AREA);
    width = std::max(width, pair.cols);
    lines.push_back(pair);
  }
  // A last row: the model from where no photo was taken (from above, behind, ...).
  if (width > 0) {
    const int views_across = 3;
    const int cell_width = width / views_across;
    const int cell_height = std::max(1, lines.front().rows);
    std::vector<cv::Mat> cells;
    for (const CalibratedView& view : ViewsFromOutside(mesh, views, views_across, cell_width, cell_height)) {
      cells.push_back(RenderMesh(mesh, view, /*front_faces_only=*/false).image);
    }
    if (!cells.empty()) {
      cv::Mat line;
      cv::hconcat(cells, line);
      lines.push_back(line);
    }
  }
  // Rows of different widths (photos of different sizes) are padded on the right.
  for (cv::Mat& line : lines) {
    if (line.cols < width) {
      cv::copyMakeBorder(line, line, 0, 0, 0, width - line.cols, cv::BORDER_CONSTANT,
                         cv::Scalar::all(0));
    }
  }
  cv::Mat preview;
  cv::vconcat(lines, preview);
  return preview;
}

}  // namespace exporter
}  // namespace raycarve
