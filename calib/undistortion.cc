#include "calib/undistortion.h"

#include <glog/logging.h>
#include <opencv2/imgproc.hpp>

#include "calib/pixel.h"

namespace raycarve {

Camera PinholeCameraFor(const Camera& camera) {
  Camera pinhole;
  pinhole.camera_id = camera.camera_id;
  pinhole.model = CameraModelId::kPinhole;
  pinhole.width = camera.width;
  pinhole.height = camera.height;
  const Eigen::Vector2d principal_point = camera.PrincipalPoint();
  pinhole.params = {
      camera.FocalLengthX(), camera.FocalLengthY(), principal_point.x(), principal_point.y()};
  return pinhole;
}

UndistortionMaps BuildUndistortionMaps(const Camera& camera) {
  UndistortionMaps maps;
  maps.pinhole = PinholeCameraFor(camera);
  const int width = static_cast<int>(camera.width);
  const int height = static_cast<int>(camera.height);
  maps.map_x.create(height, width, CV_32FC1);
  maps.map_y.create(height, width, CV_32FC1);
  for (int row = 0; row < height; ++row) {
    float* map_x = maps.map_x.ptr<float>(row);
    float* map_y = maps.map_y.ptr<float>(row);
    for (int col = 0; col < width; ++col) {
      const Eigen::Vector2d ray = maps.pinhole.CamFromImg(PixelCentre(row, col));
      const Eigen::Vector2d source = OpenCvFromColmap(camera.ImgFromCam(ray));
      map_x[col] = static_cast<float>(source.x());
      map_y[col] = static_cast<float>(source.y());
    }
  }
  return maps;
}

void UndistortImage(const UndistortionMaps& maps,
                    const cv::Mat& distorted,
                    cv::Mat* undistorted,
                    cv::Mat* valid) {
  CHECK_EQ(distorted.cols, maps.map_x.cols);
  CHECK_EQ(distorted.rows, maps.map_x.rows);
  cv::remap(distorted,
            *undistorted,
            maps.map_x,
            maps.map_y,
            cv::INTER_LINEAR,
            cv::BORDER_REPLICATE);
  valid->create(distorted.rows, distorted.cols, CV_8UC1);
  // A source position within half a pixel of the image's outer edge still lies on the image.
  const float max_x = static_cast<float>(distorted.cols) - 0.5f;
  const float max_y = static_cast<float>(distorted.rows) - 0.5f;
  for (int row = 0; row < distorted.rows; ++row) {
    const float* map_x = maps.map_x.ptr<float>(row);
    const float* map_y = maps.map_y.ptr<float>(row);
    uint8_t* valid_row = valid->ptr<uint8_t>(row);
    for (int col = 0; col < distorted.cols; ++col) {
      const bool inside = map_x[col] >= -0.5f && map_x[col] <= max_x && map_y[col] >= -0.5f &&
                          map_y[col] <= max_y;
      valid_row[col] = inside ? 255 : 0;
    }
  }
  undistorted->setTo(cv::Scalar::all(0), *valid == 0);
}

}  // namespace raycarve
