#include "calib/calibrated_view.h"

#include <algorithm>

#include <glog/logging.h>
#include <opencv2/imgproc.hpp>

#include "calib/input_error.h"
#include "calib/undistortion.h"

namespace raycarve {

double CalibratedView::Depth(const Eigen::Vector3d& world) const {
  return (cam_from_world * world).z();
}

bool CalibratedView::FramesPoint(const Eigen::Vector3d& world) const {
  if (!(Depth(world) > 0.0)) return false;
  const Eigen::Vector2d pixel = Project(world);
  if (!(pixel.x() >= 0.0 && pixel.y() >= 0.0 && pixel.x() < width && pixel.y() < height)) {
    return false;
  }
  const int col = static_cast<int>(pixel.x()), row = static_cast<int>(pixel.y());
  return valid.empty() || valid.at<uint8_t>(row, col) != 0;
}

Eigen::Matrix3d CalibratedView::WorldFromPixel() const {
  return cam_from_world.rotation.toRotationMatrix().transpose() * K.inverse();
}

CalibratedView MakeCalibratedView(const Camera& camera,
                                  const Image& image,
                                  const cv::Mat& rgb,
                                  const std::string& source,
                                  const cv::Mat& mask,
                                  const std::string& mask_source) {
  CHECK_EQ(rgb.type(), CV_8UC3);
  if (static_cast<uint64_t>(rgb.cols) != camera.width ||
      static_cast<uint64_t>(rgb.rows) != camera.height) {
    throw InputError(source + ": photo of image " + std::to_string(image.image_id) + " is " +
                     std::to_string(rgb.cols) + "x" + std::to_string(rgb.rows) + " but camera " +
                     std::to_string(camera.camera_id) + " says " + std::to_string(camera.width) +
                     "x" + std::to_string(camera.height));
  }
  CalibratedView view;
  view.image_id = image.image_id;
  view.name = image.name;
  view.width = rgb.cols;
  view.height = rgb.rows;
  view.cam_from_world = image.cam_from_world;
  view.cam_from_world.rotation.normalize();
  view.centre = view.cam_from_world.Inverse().translation;

  const Camera pinhole = PinholeCameraFor(camera);
  view.K << pinhole.params[0], 0.0, pinhole.params[2], 0.0, pinhole.params[1], pinhole.params[3],
      0.0, 0.0, 1.0;
  view.P = view.K * view.cam_from_world.ToMatrix();

  cv::Mat object;
  if (!mask.empty()) {
    CHECK_EQ(mask.type(), CV_8UC1);
    if (mask.size() != rgb.size()) {
      throw InputError(mask_source + ": mask of image " + std::to_string(image.image_id) + " is " +
                       std::to_string(mask.cols) + "x" + std::to_string(mask.rows) +
                       " but its photo is " + std::to_string(rgb.cols) + "x" +
                       std::to_string(rgb.rows));
    }
    object = (mask != 0);
  }
  if (CameraModelHasDistortion(camera.model)) {
    const UndistortionMaps maps = BuildUndistortionMaps(camera);
    UndistortImage(maps, rgb, &view.image, &view.valid);
    if (!object.empty()) {
      cv::remap(object, view.mask, maps.map_x, maps.map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT);
    }
  } else {
    view.image = rgb.clone();
    view.valid = cv::Mat(rgb.rows, rgb.cols, CV_8UC1, cv::Scalar(255));
    view.mask = object;
  }
  return view;
}

CalibratedView ReduceView(const CalibratedView& view, int factor) {
  CHECK(factor >= 1 && factor <= std::min(view.width, view.height)) << "factor " << factor;
  if (factor == 1) return view;
  CalibratedView reduced = view;
  reduced.width = view.width / factor;
  reduced.height = view.height / factor;
  const cv::Rect kept(0, 0, reduced.width * factor, reduced.height * factor);
  const cv::Size size(reduced.width, reduced.height);
  // INTER_AREA with an integer factor averages exactly the factor x factor blocks.
  cv::resize(view.image(kept), reduced.image, size, 0, 0, cv::INTER_AREA);
  // Valid where the whole block is; on the object where any of it is.
  const auto reduce_mask = [&](const cv::Mat& mask, bool need_all) {
    cv::Mat reduced_mask(size, CV_8UC1);
    for (int row = 0; row < size.height; ++row) {
      for (int col = 0; col < size.width; ++col) {
        int set = 0;
        for (int y = row * factor; y < (row + 1) * factor; ++y) {
          const uint8_t* line = mask.ptr<uint8_t>(y);
          for (int x = col * factor; x < (col + 1) * factor; ++x) set += line[x] != 0;
        }
        reduced_mask.at<uint8_t>(row, col) =
            (need_all ? set == factor * factor : set > 0) ? 255 : 0;
      }
    }
    return reduced_mask;
  };
  reduced.valid = reduce_mask(view.valid, /*need_all=*/true);
  if (!view.mask.empty()) reduced.mask = reduce_mask(view.mask, /*need_all=*/false);
  Eigen::Matrix3d scale = Eigen::Matrix3d::Identity();
  scale(0, 0) = scale(1, 1) = 1.0 / factor;
  reduced.K = scale * view.K;
  reduced.P = scale * view.P;
  return reduced;
}

namespace {

// EnlargeView's valid pixels.
cv::Mat EnlargedValid(const CalibratedView& view, int factor) {
  const cv::Size size(view.width * factor, view.height * factor);
  // Valid only where every input pixel the interpolation weighs is: a blend with the black
  // beyond an undistorted frame is no photo colour.
  cv::Mat weighed;
  cv::resize(view.valid, weighed, size, 0, 0, cv::INTER_LINEAR);
  cv::Mat valid = weighed == 255;
  if (!view.mask.empty()) {
    // Nor where it blends the object with the background: such a pixel is the colour of neither
    // (the photo's own rim pixels stay, as in the view).
    cv::Mat object;
    cv::resize(view.mask != 0, object, size, 0, 0, cv::INTER_LINEAR);
    valid &= (object == 0) | (object == 255);
  }
  return valid;
}

}  // namespace

CalibratedView EnlargeView(const CalibratedView& view, int factor) {
  CHECK(factor >= 1 && factor <= 16) << "factor " << factor;
  if (factor == 1) return view;
  CalibratedView enlarged = view;
  enlarged.width = view.width * factor;
  enlarged.height = view.height * factor;
  const cv::Size size(enlarged.width, enlarged.height);
  // OpenCV samples output pixel x at input (x + 0.5) / factor - 0.5: pixel centres in COLMAP's
  // convention scale by `factor` exactly, as K does below.
  cv::resize(view.image, enlarged.image, size, 0, 0, cv::INTER_LINEAR);
  enlarged.valid = EnlargedValid(view, factor);
  if (!view.mask.empty()) {
    cv::resize(view.mask, enlarged.mask, size, 0, 0, cv::INTER_NEAREST);
  }
  Eigen::Matrix3d scale = Eigen::Matrix3d::Identity();
  scale(0, 0) = scale(1, 1) = factor;
  enlarged.K = scale * view.K;
  enlarged.P = scale * view.P;
  return enlarged;
}

double MedianPixelFootprint(const std::vector<CalibratedView>& views, const Eigen::Vector3d& point) {
  std::vector<double> widths;
  for (const CalibratedView& view : views) {
    const double depth = view.Depth(point);
    const double focal = 0.5 * (view.K(0, 0) + view.K(1, 1));
    if (depth > 0.0 && focal > 0.0) widths.push_back(depth / focal);
  }
  if (widths.empty()) return 0.0;
  std::nth_element(widths.begin(), widths.begin() + widths.size() / 2, widths.end());
  return widths[widths.size() / 2];
}

}  // namespace raycarve
