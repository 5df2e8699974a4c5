// A small program using raycarve's libraries as an outsider would: renders a coloured point cloud
// (raycarve's cloud.ply, or COLMAP's fused.ply) into one camera of a COLMAP model and writes the
// (undistorted) photo and the render side by side.
//   render_cloud MODEL_PATH IMAGE_PATH CLOUD.ply IMAGE_ID OUTPUT.png [POINT_SIZE]
// POINT_SIZE is the splat size in world units (for a carved cloud, its voxel size); 0 or absent:
// one pixel per point.
#include <cstdio>
#include <exception>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/calibrated_view.h"
#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "export/point_renderer.h"

int main(int argc, char** argv) {
  if (argc < 6) {
    std::fprintf(stderr,
                 "usage: %s MODEL_PATH IMAGE_PATH CLOUD.ply IMAGE_ID OUTPUT.png [POINT_SIZE]\n",
                 argv[0]);
    return 1;
  }
  try {
    const raycarve::Reconstruction model = raycarve::ReadModel(argv[1]);
    const auto image = model.images.find(static_cast<raycarve::image_t>(std::stoul(argv[4])));
    if (image == model.images.end()) throw raycarve::InputError(std::string("no image ") + argv[4]);
    const std::string photo_path = std::string(argv[2]) + "/" + image->second.name;
    cv::Mat bgr = cv::imread(photo_path, cv::IMREAD_COLOR | cv::IMREAD_IGNORE_ORIENTATION);
    if (bgr.empty()) throw raycarve::InputError(photo_path + ": cannot read the photo");
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    const raycarve::CalibratedView view = raycarve::MakeCalibratedView(
        model.cameras.at(image->second.camera_id), image->second, rgb, photo_path);
    const double point_size = argc > 6 ? std::stod(argv[6]) : 0.0;
    const raycarve::exporter::Rendering rendering = raycarve::exporter::RenderPoints(
        raycarve::exporter::ReadPointCloudPly(argv[3]), view, point_size);
    cv::Mat render = rendering.image.clone();
    render.setTo(cv::Scalar(255, 0, 255), rendering.silhouette == 0);  // magenta: nothing drawn
    cv::Mat side_by_side;
    cv::hconcat(view.image, render, side_by_side);
    cv::cvtColor(side_by_side, side_by_side, cv::COLOR_RGB2BGR);
    if (!cv::imwrite(argv[5], side_by_side)) {
      throw raycarve::InputError(std::string(argv[5]) + ": cannot write");
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "render_cloud: error: %s\n", error.what());
    return 1;
  }
  return 0;
}
