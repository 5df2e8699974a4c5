#include <iostream>

#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "export/background_check.h"
#include "export/point_cloud_io.h"
#include "calib/view_reader.h"
#include "plugin/commands.h"
#include "plugin/option_parser.h"
#include "pipeline/json_writer.h"
#include "pipeline/output_files.h"
#include "pipeline/workspace.h"

namespace raycarve {

int RunCheckBackground(int argc, char** argv) {
  std::string workspace_path, input_path, image_path, cloud, background = "auto", output_path;
  ViewReaderOptions view_options;
  OptionParser parser(
      "check_background",
      "Measures how much of a point cloud is background: the share of its points that project "
      "onto background, in more than half of the masked views that see them. Masks come from "
      "--mask_path or, by default, from the photos' backdrop colour.");
  parser.AddRequired("cloud_path", &cloud, "the point cloud to check (PLY, e.g. raycarve's cloud.ply)");
  parser.AddDeprecatedName("input", "cloud_path");
  parser.AddDefault("workspace_path", &workspace_path, "COLMAP project of the photos");
  parser.AddDefault("input_path", &input_path, "model folder, overriding the workspace's");
  parser.AddDefault("image_path", &image_path, "photo folder, overriding the workspace's");
  parser.AddDefault("mask_path", &view_options.mask_path, "folder of object masks");
  parser.AddDefault("background_colour", &background, "without --mask_path: auto or R,G,B");
  parser.AddDefault("background_tolerance", &view_options.background.tolerance,
                    "RGB distance from the backdrop colour beyond which a pixel is object");
  parser.AddDefault("output_path", &output_path, "also write the JSON result to this file");
  if (!parser.Parse(argc, argv)) return 0;
  view_options.background.mode = ParseBackground(background, &view_options.background.colour);
  if (view_options.mask_path.empty() &&
      view_options.background.mode == BackgroundOptions::Mode::kNone) {
    throw InputError("raycarve check_background: needs masks: --mask_path, or --background_colour auto|R,G,B");
  }
  const WorkspacePaths paths = ResolveWorkspace(workspace_path, input_path, image_path);
  if (!output_path.empty()) {
    CheckOutputFileOutside(output_path, cloud, "input cloud");
    CheckOutputFileOutside(output_path, paths.model_path, "input model");
    CheckOutputFileOutside(output_path, paths.image_path, "photo folder");
    if (!view_options.mask_path.empty()) {
      CheckOutputFileOutside(output_path, view_options.mask_path, "mask folder");
    }
  }
  const std::vector<CalibratedView> views =
      ReadCalibratedViews(ReadModel(paths.model_path), paths.image_path, view_options, nullptr);
  std::vector<Eigen::Vector3f> points;
  for (const exporter::ColouredPoint& point : exporter::ReadPointCloudPly(cloud)) {
    points.push_back(point.xyz);
  }
  const exporter::BackgroundCheck check = exporter::CheckBackground(points, views);
  JsonWriter json;
  json.BeginObject()
      .Key("input").Value(cloud)
      .Key("num_points").Value(static_cast<uint64_t>(check.num_points))
      .Key("on_background").Value(static_cast<uint64_t>(check.on_background))
      .Key("share").Value(check.share)
      .EndObject();
  std::cout << "check_background " << cloud << ": " << check.Summary() << "\n" << json.str();
  if (!output_path.empty()) WriteTextFileAtomically(output_path, json.str());
  return 0;
}

}  // namespace raycarve
