#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <numeric>
#include <sstream>

#include <glog/logging.h>

#include "calib/input_error.h"
#include "calib/middlebury.h"
#include "calib/model_reader.h"
#include "calib/model_writer.h"
#include "plugin/commands.h"
#include "plugin/json_writer.h"
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

void AddBoundsFlags(OptionParser* parser, BoundsFlags* flags) {
  parser->AddDefault("min_track_length", &flags->options.min_track_length,
                     "sparse points seen in fewer images are ignored when bounding the volume");
  parser->AddDefault("max_reprojection_error", &flags->options.max_reprojection_error,
                     "sparse points with a larger mean reprojection error (px) are ignored; "
                     "<= 0 keeps all");
  parser->AddDefault("min_framed_share", &flags->options.min_framed_share,
                     "sparse points framed by fewer photos than this share of the best framed "
                     "points' count are the room around the object, left out when they are more "
                     "than twice --trim_fraction of the points (0 keeps all)");
  parser->AddDefault("trim_fraction", &flags->options.trim_fraction,
                     "fraction of points dropped at each end of each axis (outliers)");
  parser->AddDefault("min_points", &flags->options.min_points,
                     "fewest usable sparse points that may bound the volume (else --bbox is asked for)");
  parser->AddDefault("margin", &flags->options.margin,
                     "added on every side, as a fraction of the largest extent");
  parser->AddDefault("bbox", &flags->bbox,
                     "explicit volume min_x,min_y,min_z,max_x,max_y,max_z (world units); "
                     "overrides the sparse points");
}

Bounds ResolveBounds(const Reconstruction& reconstruction,
                     const BoundsFlags& flags,
                     const std::string& source) {
  if (!flags.bbox.empty()) {
    std::vector<double> values;
    std::stringstream stream(flags.bbox);
    stream.imbue(std::locale::classic());
    std::string item;
    while (std::getline(stream, item, ',')) {
      char* end = nullptr;
      const double value = std::strtod(item.c_str(), &end);
      if (item.empty() || end != item.c_str() + item.size()) {
        throw InputError("--bbox: '" + item + "' is not a number");
      }
      values.push_back(value);
    }
    if (values.size() != 6) {
      throw InputError("--bbox: expected 6 comma-separated numbers, found " +
                       std::to_string(values.size()));
    }
    return ExplicitBounds(Eigen::Vector3d(values[0], values[1], values[2]),
                          Eigen::Vector3d(values[3], values[4], values[5]));
  }
  std::string reason;
  if (!flags.options.IsValid(&reason)) throw InputError("bounds options: " + reason);
  return ComputeBounds(reconstruction, flags.options, source);
}

namespace {
// No output replaces an option file that was read (--project_path).
void CheckNotAnOptionFile(const std::string& output_path) {
  if (output_path.empty()) return;
  for (const std::string& file : OptionFilesRead()) {
    if (std::filesystem::weakly_canonical(output_path) == std::filesystem::weakly_canonical(file)) {
      throw InputError(output_path + ": the output is the option file (--project_path " + file +
                       "); raycarve never overwrites its input, choose another --output_path");
    }
  }
}
}  // namespace

void CheckOutputDoesNotOverwrite(const std::string& output_path,
                                 const std::string& input_path,
                                 const std::string& what) {
  CheckNotAnOptionFile(output_path);
  if (output_path.empty() || input_path.empty()) return;
  if (std::filesystem::weakly_canonical(output_path) ==
      std::filesystem::weakly_canonical(input_path)) {
    throw InputError(output_path + ": the output is the " + what + " (" + input_path +
                     "); raycarve never overwrites its input, choose another --output_path");
  }
}

void CheckOutputFileOutside(const std::string& output_file,
                            const std::string& input_path,
                            const std::string& what) {
  CheckNotAnOptionFile(output_file);
  if (output_file.empty() || input_path.empty()) return;
  namespace fs = std::filesystem;
  const fs::path output = fs::weakly_canonical(output_file);
  const fs::path input = fs::weakly_canonical(input_path);
  // The output is the input, or lies inside it (a folder), through links, dots and slashes.
  const auto [input_end, output_at] = std::mismatch(input.begin(), input.end(), output.begin(), output.end());
  if (input_end == input.end()) {
    throw InputError(output_file + ": the output " +
                     (output == input ? std::string("is the ") : std::string("lies inside the ")) +
                     what + " (" + input_path +
                     "); raycarve never overwrites its input, choose another --output_path");
  }
}

std::filesystem::path OutputFileInside(const std::string& folder,
                                       const std::string& relative_name,
                                       const std::vector<std::pair<std::string, std::string>>& inputs) {
  namespace fs = std::filesystem;
  const fs::path name(relative_name);
  const fs::path root = fs::weakly_canonical(folder);
  const fs::path path = fs::weakly_canonical(root / name);
  const auto [root_end, path_at] = std::mismatch(root.begin(), root.end(), path.begin(), path.end());
  if (name.is_absolute() || root_end != root.end() || path == root) {
    throw InputError(folder + ": the image name '" + relative_name +
                     "' would write outside this output folder; raycarve refuses it");
  }
  for (const auto& [input, what] : inputs) CheckOutputFileOutside(path.string(), input, what);
  return path;
}

std::string DescribeModelText(const Reconstruction& reconstruction,
                              const std::string& model_path,
                              const Bounds& bounds) {
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
       << bounds.Summary() << "\n";
  return text.str();
}

std::string DescribeModelJson(const Reconstruction& reconstruction,
                              const std::string& model_path,
                              const Bounds& bounds) {
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
  BoundsFlags bounds_flags;
  OptionParser parser("model_info",
                      "Prints a COLMAP sparse model's cameras, images and points, and the volume "
                      "raycarve would carve.");
  parser.AddRequired("input_path", &input_path, "COLMAP model folder (cameras/images/points3D)");
  parser.AddDefault("format", &format, "what to print", {"text", "json"});
  parser.AddDefault("output_path", &output_path, "also write the JSON description to this file");
  AddBoundsFlags(&parser, &bounds_flags);
  if (!parser.Parse(argc, argv)) return 0;

  const Reconstruction reconstruction = ReadModel(input_path);
  const Bounds bounds = ResolveBounds(reconstruction, bounds_flags, input_path);
  const std::string json = DescribeModelJson(reconstruction, input_path, bounds);
  std::cout << (format == "json" ? json : DescribeModelText(reconstruction, input_path, bounds));
  if (!output_path.empty()) {
    CheckOutputFileOutside(output_path, input_path, "input model");
    WriteTextFileAtomically(output_path, json);
  }
  return 0;
}

int RunModelConverter(int argc, char** argv) {
  std::string input_path, output_path, output_type = "BIN";
  OptionParser parser("model_converter",
                      "Reads a COLMAP model (binary or text) and writes it in the other form, "
                      "as `colmap model_converter` does.");
  parser.AddRequired("input_path", &input_path, "COLMAP model folder to read");
  parser.AddRequired("output_path", &output_path, "folder to write (created; must differ from input)");
  parser.AddDefault("output_type", &output_type, "format to write", {"BIN", "TXT"});
  if (!parser.Parse(argc, argv)) return 0;
  CheckOutputDoesNotOverwrite(output_path, input_path, "input model");
  const Reconstruction reconstruction = ReadModel(input_path);
  WriteModel(reconstruction, output_path, ModelFormatFromString(output_type));
  LOG(INFO) << "wrote " << reconstruction.cameras.size() << " cameras, "
            << reconstruction.images.size() << " images, " << reconstruction.points3D.size()
            << " points to " << output_path << " (" << output_type << ")";
  return 0;
}

int RunImportMiddlebury(int argc, char** argv) {
  std::string input_path, image_path, output_path, output_type = "TXT";
  MiddleburyImportOptions options;
  OptionParser parser("import_middlebury",
                      "Converts a Middlebury multi-view calibration file (*_par.txt) into a "
                      "COLMAP model (PINHOLE cameras, no 3D points).");
  parser.AddRequired("input_path", &input_path, "the *_par.txt calibration file");
  parser.AddRequired("image_path", &image_path, "folder of the photos (their sizes are read)");
  parser.AddRequired("output_path", &output_path, "model folder to write (created)");
  parser.AddDefault("output_type", &output_type, "format to write", {"BIN", "TXT"});
  parser.AddDefault("principal_point_offset", &options.principal_point_offset,
                    "added to (k13, k23): 0.5 reads K with pixel centres at integers, 0 copies it");
  if (!parser.Parse(argc, argv)) return 0;
  std::string reason;
  if (!options.IsValid(&reason)) throw InputError("--principal_point_offset: " + reason);
  CheckOutputDoesNotOverwrite(output_path, image_path, "photo folder");
  const Reconstruction reconstruction = ImportMiddlebury(input_path, image_path, options);
  WriteModel(reconstruction, output_path, ModelFormatFromString(output_type));
  LOG(INFO) << "imported " << reconstruction.images.size() << " images ("
            << reconstruction.cameras.size() << " cameras) from " << input_path << " into "
            << output_path;
  return 0;
}

}  // namespace raycarve
