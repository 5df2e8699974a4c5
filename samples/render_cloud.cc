// A small program using raycarve's libraries as an outsider would: splats a coloured point cloud
// (raycarve's cloud.ply, or COLMAP's fused.ply) into one camera of a COLMAP model with a depth
// buffer, and writes the photo and the render side by side.
//   render_cloud MODEL_PATH IMAGE_PATH CLOUD.ply IMAGE_ID OUTPUT.png [SPLAT_RADIUS_PX]
#include <cstdio>
#include <exception>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "export/point_cloud_io.h"

int main(int argc, char** argv) {
  if (argc < 6) {
    std::fprintf(stderr,
                 "usage: %s MODEL_PATH IMAGE_PATH CLOUD.ply IMAGE_ID OUTPUT.png [RADIUS]\n",
                 argv[0]);
    return 1;
  }
  try {
    const raycarve::Reconstruction model = raycarve::ReadModel(argv[1]);
    const auto points = raycarve::exporter::ReadPointCloudPly(argv[3]);
    const auto image = model.images.find(static_cast<raycarve::image_t>(std::stoul(argv[4])));
    if (image == model.images.end()) throw raycarve::InputError(std::string("no image ") + argv[4]);
    const raycarve::Camera& camera = model.cameras.at(image->second.camera_id);
    const std::string photo_path = std::string(argv[2]) + "/" + image->second.name;
    const cv::Mat photo = cv::imread(photo_path, cv::IMREAD_COLOR);
    if (photo.empty()) throw raycarve::InputError(photo_path + ": cannot read the photo");
    const int radius = argc > 6 ? std::stoi(argv[6]) : 1;
    cv::Mat render(photo.size(), CV_8UC3, cv::Scalar(255, 0, 255));  // magenta: nothing
    cv::Mat depth(photo.size(), CV_32F, cv::Scalar(1e30));
    for (const auto& point : points) {
      const Eigen::Vector3d in_camera = image->second.cam_from_world * point.xyz.cast<double>();
      if (in_camera.z() <= 0.0) continue;
      const Eigen::Vector2d pixel = camera.ImgFromCam(in_camera.hnormalized());
      const int col = static_cast<int>(pixel.x()), row = static_cast<int>(pixel.y());
      for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
          const int c = col + dx, r = row + dy;
          if (c < 0 || r < 0 || c >= render.cols || r >= render.rows) continue;
          if (in_camera.z() >= depth.at<float>(r, c)) continue;
          depth.at<float>(r, c) = static_cast<float>(in_camera.z());
          render.at<cv::Vec3b>(r, c) = cv::Vec3b(point.rgb[2], point.rgb[1], point.rgb[0]);
        }
      }
    }
    cv::Mat side_by_side;
    cv::hconcat(photo, render, side_by_side);
    if (!cv::imwrite(argv[5], side_by_side)) throw raycarve::InputError(std::string(argv[5]) + ": cannot write");
  } catch (const std::exception& error) {
    std::fprintf(stderr, "render_cloud: error: %s\n", error.what());
    return 1;
  }
  return 0;
}
