// raycarve model_info: a model's cameras, images, points and the volume it would carve.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <numeric>
#include <sstream>

#include <glog/logging.h>

#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "pipeline/project.h"
#include "plugin/carve_flags.h"
#include "plugin/commands.h"
#include "pipeline/json_writer.h"
#include "pipeline/output_files.h"
#include "plugin/option_parser.h"

namespace raycarve {
namespace {

struct PointStatistics {
  double mean_track_length = 0.0;
  double mean_error = 0.0;
  size_t num_observations = 0;
};

PointStatistics ComputePointStatistics(const Reconstruction& reconstruction) {
  PointStatistics statistics;
  if (reconstruction.points3D.empty()) return statistics;
  double error_sum = 0.0;
  for (const auto& [id, point3D] : reconstruction.points3D) {
    statistics.num_observations += point3D.track.size();
    error_sum += point3D.error;
  }
  const double count = static_cast<double>(reconstruction.points3D.size());
  statistics.mean_track_length = statistics.num_observations / count;
  statistics.mean_error = error_sum / count;
  return statistics;
}

}  // namespace

std::string DescribeModelText(const Reconstruction& reconstruction,
                              const std::string& model_path,
                              const Bounds& bounds,
                              const std::string& bounds_error) {
  const PointStatistics points = ComputePointStatistics(reconstruction);
  std::ostringstream text;
  text << "model: " << model_path << "\n"
       << "cameras: " << reconstruction.cameras.size() << "\n";
  for (const auto& [id, camera] : reconstruction.cameras) {
    text << "  camera " << id << ": " << CameraModelName(camera.model) << " " << camera.width
         << "x" << camera.height << " params";
    for (double p : camera.params) text << " " << p;
    text << "\n";
  }
  text << "images: " << reconstruction.images.size() << " registered\n";
  char line[256];
  std::snprintf(line, sizeof(line), "  %6s  %-28s %6s %9s  %s\n", "id", "name", "camera",
                "observed", "centre");
  text << line;
  for (const auto& [id, image] : reconstruction.images) {
    const size_t observed = std::count_if(
        image.points2D.begin(), image.points2D.end(),
        [](const Point2D& p) { return p.point3D_id != kInvalidPoint3DId; });
    const Eigen::Vector3d centre = image.ProjectionCenter();
    // The name apart: it may be longer than any fixed buffer.
    std::string name = image.name;
    if (name.size() < 28) name.append(28 - name.size(), ' ');
    std::snprintf(line, sizeof(line), "  %6u  ", id);
    text << line << name;
    std::snprintf(line, sizeof(line), " %6u %9zu  (%.4g, %.4g, %.4g)\n", image.camera_id, observed,
                  centre.x(), centre.y(), centre.z());
    text << line;
  }
  text << "points3D: " << reconstruction.points3D.size() << ", mean track length "
       << points.mean_track_length << ", mean reprojection error " << points.mean_error
       << " px\n"
       << (bounds_error.empty() ? bounds.Summary() : "bounds: none (" + bounds_error + ")") << "\n";
  return text.str();
}

std::string DescribeModelJson(const Reconstruction& reconstruction,
                              const std::string& model_path,
                              const Bounds& bounds,
                              const std::string& bounds_error) {
  const PointStatistics points = ComputePointStatistics(reconstruction);
  JsonWriter json;
  json.BeginObject().Key("model_path").Value(model_path);
  json.Key("cameras").BeginArray();
  for (const auto& [id, camera] : reconstruction.cameras) {
    json.BeginObject()
        .Key("camera_id").Value(static_cast<uint64_t>(id))
        .Key("model").Value(CameraModelName(camera.model))
        .Key("width").Value(camera.width)
        .Key("height").Value(camera.height)
        .Key("params").Value(camera.params)
        .EndObject();
  }
  json.EndArray();
  json.Key("images").BeginArray();
  for (const auto& [id, image] : reconstruction.images) {
    const Eigen::Quaterniond& q = image.cam_from_world.rotation;
    json.BeginObject()
        .Key("image_id").Value(static_cast<uint64_t>(id))
        .Key("name").Value(image.name)
        .Key("camera_id").Value(static_cast<uint64_t>(image.camera_id))
        .Key("qvec").Value(std::vector<double>{q.w(), q.x(), q.y(), q.z()})
        .Key("tvec").Value(JsonArray(image.cam_from_world.translation))
        .Key("centre").Value(JsonArray(image.ProjectionCenter()))
        .Key("num_points2D").Value(static_cast<uint64_t>(image.points2D.size()))
        .EndObject();
  }
  json.EndArray();
  json.Key("points3D").BeginObject()
      .Key("count").Value(static_cast<uint64_t>(reconstruction.points3D.size()))
      .Key("num_observations").Value(static_cast<uint64_t>(points.num_observations))
      .Key("mean_track_length").Value(points.mean_track_length)
      .Key("mean_reprojection_error").Value(points.mean_error)
      .EndObject();
  if (!bounds_error.empty()) {
    json.Key("bounds").BeginObject().Key("error").Value(bounds_error).EndObject();
    json.EndObject();
    return json.str();
  }
  json.Key("bounds").BeginObject()
      .Key("min").Value(JsonArray(bounds.box.min()))
      .Key("max").Value(JsonArray(bounds.box.max()))
      .Key("extent").Value(JsonArray(bounds.box.sizes()))
      .Key("explicit").Value(bounds.is_explicit)
      .Key("num_points").Value(bounds.num_points)
      .Key("num_used").Value(bounds.num_used)
      .Key("num_short_track").Value(bounds.num_short_track)
      .Key("num_high_error").Value(bounds.num_high_error)
      .Key("num_trimmed_outside").Value(bounds.num_trimmed_outside)
      .EndObject();
  json.EndObject();
  return json.str();
}

int RunModelInfo(int argc, char** argv) {
  std::string input_path;
  std::string format = "text";
  std::string output_path;
  BoundsRequest bounds_flags;
  OptionParser parser("model_info",
                      "Prints a COLMAP sparse model's cameras, images and points, and the volume "
                      "raycarve would carve.");
  parser.AddRequired("input_path", &input_path, "COLMAP model folder (cameras/images/points3D)");
  parser.AddDefault("format", &format, "what to print", {"text", "json"});
  parser.AddDefault("output_path", &output_path, "also write the JSON description to this file");
  AddBoundsFlags(&parser, &bounds_flags);
  if (!parser.Parse(argc, argv)) return 0;

  const Reconstruction reconstruction = ReadModel(input_path);
  // A model whose points cannot bound a volume (one image, too few points) is still described.
  Bounds bounds;
  std::string bounds_error;
  try {
    bounds = ResolveBounds(reconstruction, bounds_flags, input_path);
  } catch (const InputError& error) {
    bounds_error = error.what();
  }
  const std::string json = DescribeModelJson(reconstruction, input_path, bounds, bounds_error);
  std::cout << (format == "json" ? json
                                 : DescribeModelText(reconstruction, input_path, bounds, bounds_error));
  if (!output_path.empty()) {
    CheckOutputFileOutside(output_path, input_path, "input model");
    WriteTextFileAtomically(output_path, json);
  }
  return 0;
}

}  // namespace raycarve
