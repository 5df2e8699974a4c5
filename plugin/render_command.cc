// raycarve render: a coloured cloud drawn into the cameras of a COLMAP model.
#include <algorithm>
#include <cstdio>
#include <string>
#include <filesystem>
#include <set>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/atomic_file.h"
#include "calib/image_reader.h"
#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "export/mesh_file_reader.h"
#include "export/mesh_renderer.h"
#include "export/point_cloud_io.h"
#include "export/point_renderer.h"
#include "calib/view_reader.h"
#include "plugin/commands.h"
#include "plugin/option_parser.h"
#include "pipeline/json_writer.h"
#include "pipeline/output_files.h"
#include "pipeline/project.h"

namespace raycarve {
namespace {

// Memory a rendered pixel holds: the photo and the render (RGB), their side-by-side image, the
// depth buffer, the silhouette and the BGR copies written.
constexpr double kBytesPerRenderedPixel = 24.0;

// The model to draw: a mesh (PLY with faces; glTF or OBJ, drawn with its texture) or a cloud
// (splats; it may be empty).
void ReadDrawable(const std::string& input, exporter::TriangleMesh* mesh,
                  std::vector<exporter::ColouredPoint>* points) {
  if (exporter::IsGltfPath(input) || exporter::IsObjPath(input)) {
    *mesh = exporter::ReadModelFile(input);
    return;
  }
  *points = exporter::ReadPointCloudPly(input);
  if (!points->empty()) *mesh = exporter::ReadMeshOrCloudPly(input);  // no triangles: a cloud
}

std::set<std::string> SplitNames(const std::string& names) {
  std::set<std::string> wanted;
  std::stringstream list(names);
  std::string name;
  while (std::getline(list, name, ',')) {
    if (!name.empty()) wanted.insert(name);
  }
  return wanted;
}

// The output folder, created: never the model's, the photos' or the drawn model's place; and
// the largest camera's images must fit in memory (each camera is drawn in turn).
void PrepareOutput(const Reconstruction& model, const std::string& model_path,
                   const std::string& input, const std::string& image_path,
                   const std::string& output_path) {
  CheckOutputFileOutside(output_path, model_path, "input model");
  CheckOutputFileOutside(output_path, input, "input model file");
  if (!image_path.empty()) CheckOutputFileOutside(output_path, image_path, "photo folder");
  std::error_code error;
  std::filesystem::create_directories(output_path, error);
  if (error) throw InputError(output_path + ": cannot create: " + error.message());
  double largest_pixels = 0.0;
  for (const auto& [id, camera] : model.cameras) {
    largest_pixels = std::max(largest_pixels, static_cast<double>(camera.width) * camera.height);
  }
  CheckFitsInMemory(kBytesPerRenderedPixel * largest_pixels,
                    "raycarve render: a camera of " + model_path,
                    std::to_string(static_cast<int>(largest_pixels)) + " pixels, " +
                        std::to_string(static_cast<int>(kBytesPerRenderedPixel)) + " bytes each",
                    "render a model with smaller cameras");
}

// One camera's render, silhouette and (with photos) side-by-side images.
void RenderImage(const Camera& camera, const Image& image, const exporter::TriangleMesh& mesh,
                 const std::vector<exporter::ColouredPoint>& points, double point_size,
                 const std::string& image_path, const std::string& output_path) {
  cv::Mat rgb(static_cast<int>(camera.height), static_cast<int>(camera.width), CV_8UC3,
              cv::Scalar(0, 0, 0));
  std::string source = "(no photo)";
  if (!image_path.empty()) {
    source = image_path + "/" + image.name;
    const cv::Mat bgr = ReadImage(source, cv::IMREAD_COLOR);
    if (bgr.empty()) throw InputError(source + ": cannot read the photo of image " + image.name);
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  }
  const CalibratedView view = MakeCalibratedView(camera, image, rgb, source);
  const exporter::Rendering rendering = mesh.empty()
                                            ? exporter::RenderPoints(points, view, point_size)
                                            : exporter::RenderMesh(mesh, view);
  const std::string file = std::filesystem::path(image.name).filename().string();
  for (const char* suffix : {".render.png", ".silhouette.png", ".side.png"}) {
    CheckNoLinkInside(output_path, file + suffix);
  }
  const std::string stem = (std::filesystem::path(output_path) / file).string();
  cv::Mat bgr;
  cv::cvtColor(rendering.image, bgr, cv::COLOR_RGB2BGR);
  WriteImageAtomically(stem + ".render.png", bgr);
  WriteImageAtomically(stem + ".silhouette.png", rendering.silhouette);
  if (!image_path.empty()) {
    cv::Mat side;
    cv::hconcat(view.image, rendering.image, side);
    cv::cvtColor(side, side, cv::COLOR_RGB2BGR);
    WriteImageAtomically(stem + ".side.png", side);
  }
}

}  // namespace

int RunRender(int argc, char** argv) {
  std::string input, model_path, image_path, output_path, names;
  double point_size = 0.0;
  OptionParser parser(
      "render",
      "Draws a coloured point cloud (raycarve's cloud.ply, COLMAP's fused.ply; z-buffered splats) "
      "or a mesh (PLY with faces; glTF .glb/.gltf or OBJ with its texture) into cameras of a COLMAP "
      "model: writes <name>.render.png and <name>.silhouette.png per "
      "camera (undistorted, pinhole), and with --image_path <name>.side.png (photo | render).");
  parser.AddRequired("cloud_path", &input,
                     "the model to draw: a PLY point cloud or mesh, or a glTF (.glb, .gltf) or OBJ mesh");
  parser.AddDeprecatedName("input", "cloud_path");
  parser.AddRequired("input_path", &model_path, "COLMAP model whose cameras draw it");
  parser.AddRequired("output_path", &output_path, "folder for the images (created)");
  parser.AddDefault("image_path", &image_path, "the model's photos, for side-by-side images");
  parser.AddDefault("image_names", &names, "comma-separated image names (default: every image)");
  parser.AddDefault("point_size", &point_size,
                    "splat size in world units (a carved cloud's voxel size); 0: one pixel");
  if (!parser.Parse(argc, argv)) return 0;
  if (!(point_size >= 0.0)) throw InputError("raycarve render: --point_size must be >= 0");
  const Reconstruction model = ReadModel(model_path);
  exporter::TriangleMesh mesh;
  std::vector<exporter::ColouredPoint> points;
  ReadDrawable(input, &mesh, &points);
  const std::set<std::string> wanted = SplitNames(names);
  PrepareOutput(model, model_path, input, image_path, output_path);
  int rendered = 0;
  std::set<std::string> found;
  for (const auto& [id, image] : model.images) {
    if (!wanted.empty() && !wanted.count(image.name)) continue;
    found.insert(image.name);
    RenderImage(model.cameras.at(image.camera_id), image, mesh, points, point_size, image_path,
                output_path);
    ++rendered;
  }
  for (const std::string& missing : wanted) {
    if (!found.count(missing)) {
      throw InputError(model_path + ": no image named '" + missing + "' in the model");
    }
  }
  const std::string drawn = mesh.empty() ? std::to_string(points.size()) + " points"
                                          : std::to_string(mesh.triangles.size()) + " triangles" +
                                                (mesh.textured() ? " (textured)" : "");
  std::printf("render: drew %s into %d cameras of %s; images in %s\n", drawn.c_str(), rendered,
              model_path.c_str(), output_path.c_str());
  return 0;
}

}  // namespace raycarve
