#include "export/preview.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "export/mesh_renderer.h"

namespace raycarve {
namespace exporter {

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
