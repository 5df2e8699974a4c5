#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include <glog/logging.h>
#include <opencv2/imgproc.hpp>

#include "calib/atomic_file.h"
#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "calib/view_reader.h"
#include "plugin/calibrate.h"
#include "pipeline/project.h"
#include "plugin/carve_flags.h"
#include "plugin/commands.h"
#include "plugin/option_parser.h"
#include "pipeline/json_writer.h"
#include "pipeline/output_files.h"
#include "pipeline/workspace.h"

namespace raycarve {
namespace {

double Median(std::vector<double> values) {
  if (values.empty()) return std::nan("");
  const size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + middle, values.end());
  return values[middle];
}

using OutputPair = std::pair<std::filesystem::path, std::filesystem::path>;  // photo, mask

// Where each view's undistorted photo and validity mask go under `root`, every name checked
// before the first file is written.
std::vector<OutputPair> PlanUndistortedOutputs(const LoadedProject& project,
                                               const ViewReaderOptions& view_options,
                                               const std::filesystem::path& root) {
  std::vector<OutputPair> targets;
  std::error_code error;
  // COLMAP's conventions: photos keep their names (and format), masks are <name>.png.
  std::vector<std::pair<std::string, std::string>> inputs = {
      {project.model_path, "input model"}, {project.image_path, "photo folder"}};
  if (!view_options.mask_path.empty()) inputs.emplace_back(view_options.mask_path, "mask folder");
  // Every name checked before the first file is written.
  for (const CalibratedView& view : project.views) {
    // In this order: the photo's name is the one a user gave.
    CheckNoLinkInside(root.string(), "undistorted/" + view.name);
    CheckNoLinkInside(root.string(), "masks/" + view.name + ".png");
    std::filesystem::path photo = OutputFileInside((root / "undistorted").string(), view.name, inputs);
    std::filesystem::path mask = OutputFileInside((root / "masks").string(), view.name + ".png", inputs);
    targets.emplace_back(std::move(photo), std::move(mask));
  }
  // Folders in the output that no earlier run wrote (no report.json beside them) are the
  // user's (photos, masks): never written into.
  const bool ours = std::filesystem::exists(root / "report.json");
  for (const char* folder : {"undistorted", "masks"}) {
    if (!ours && std::filesystem::is_directory(root / folder) &&
        !std::filesystem::is_empty(root / folder, error)) {
      throw InputError((root / folder).string() +
                       ": already holds files that raycarve did not write (no report.json "
                       "beside it); calibrate would write there: give another --output_path");
    }
  }
  return targets;
}

// The undistorted photos and masks, into the staging folder `stage` at their places under `root`.
void WriteUndistorted(const std::vector<CalibratedView>& views,
                      const std::vector<OutputPair>& targets,
                      const std::filesystem::path& root,
                      const std::filesystem::path& stage) {
  std::error_code error;
  const std::filesystem::path canonical_root = std::filesystem::weakly_canonical(root);
  for (size_t v = 0; v < targets.size(); ++v) {
    const CalibratedView& view = views[v];
    const std::filesystem::path photo =
        stage / std::filesystem::relative(targets[v].first, canonical_root);
    const std::filesystem::path mask =
        stage / std::filesystem::relative(targets[v].second, canonical_root);
    for (const std::filesystem::path& folder : {photo.parent_path(), mask.parent_path()}) {
      std::filesystem::create_directories(folder, error);
      if (error) throw InputError(folder.string() + ": cannot create: " + error.message());
    }
    cv::Mat bgr;
    cv::cvtColor(view.image, bgr, cv::COLOR_RGB2BGR);
    WriteImageAtomically(photo.string(), bgr);
    WriteImageAtomically(mask.string(), view.valid);
  }
}

}  // namespace

CalibrationReport CalibrateProject(const Reconstruction& reconstruction,
                                   const std::vector<CalibratedView>& views,
                                   const Bounds& bounds) {
  CalibrationReport report;
  report.bounds = bounds;
  for (const CalibratedView& view : views) {
    const Image& image = reconstruction.images.at(view.image_id);
    const Camera& camera = reconstruction.cameras.at(image.camera_id);
    ViewCheck check;
    check.image_id = view.image_id;
    check.name = view.name;
    std::vector<double> errors;
    for (const Point2D& point2D : image.points2D) {
      if (point2D.point3D_id == kInvalidPoint3DId) continue;
      const Eigen::Vector3d& xyz = reconstruction.points3D.at(point2D.point3D_id).xyz;
      if (view.Depth(xyz) <= 0.0) {
        ++check.num_behind;
        continue;
      }
      // The observation, moved from the photo's distorted pixels into the view's pinhole pixels.
      const Eigen::Vector2d normalized = camera.CamFromImg(point2D.xy);
      if (!normalized.allFinite()) continue;
      const Eigen::Vector2d observed = (view.K * normalized.homogeneous()).hnormalized();
      errors.push_back((view.Project(xyz) - observed).norm());
    }
    check.num_observations = static_cast<int>(errors.size());
    if (!errors.empty()) {
      double sum = 0.0;
      for (double e : errors) sum += e;
      check.mean_error = sum / errors.size();
      check.median_error = Median(errors);
      check.max_error = *std::max_element(errors.begin(), errors.end());
    }
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d point = bounds.box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
      if (view.Depth(point) <= 0.0) {
        check.box_in_front = false;
        continue;
      }
      const Eigen::Vector2d pixel = view.Project(point);
      if (pixel.x() >= 0 && pixel.y() >= 0 && pixel.x() <= view.width && pixel.y() <= view.height) {
        ++check.box_corners_in_image;
      }
    }
    int valid = cv::countNonZero(view.valid);
    check.valid_fraction = static_cast<double>(valid) / (view.width * view.height);
    report.views.push_back(check);
  }
  std::vector<double> all_means;
  double weighted_sum = 0.0;
  for (const ViewCheck& check : report.views) {
    report.num_observations += check.num_observations;
    weighted_sum += check.mean_error * check.num_observations;
    report.max_error = std::max(report.max_error, check.max_error);
  }
  if (report.num_observations > 0) report.mean_error = weighted_sum / report.num_observations;
  return report;
}

std::string CalibrationReport::Table() const {
  std::string text;
  char line[256];
  std::snprintf(line, sizeof(line), "%6s  %-24s %7s %10s %10s %10s %8s %7s\n", "image", "name",
                "points", "mean px", "median px", "max px", "box in", "valid");
  text += line;
  for (const ViewCheck& check : views) {
    std::snprintf(line, sizeof(line), "%6u  %-24s %7d %10.2e %10.2e %10.2e %6d/8 %6.1f%%\n",
                  check.image_id, check.name.c_str(), check.num_observations, check.mean_error,
                  check.median_error, check.max_error, check.box_corners_in_image,
                  100.0 * check.valid_fraction);
    text += line;
  }
  std::snprintf(line, sizeof(line),
                "all: %d observations, mean reprojection error %.3g px, max %.3g px\n",
                num_observations, mean_error, max_error);
  text += line;
  return text;
}

std::string CalibrationReport::Json(const std::string& model_path,
                                    const std::string& image_path,
                                    const std::vector<CalibratedView>& calibrated) const {
  JsonWriter json;
  json.BeginObject()
      .Key("model_path").Value(model_path)
      .Key("image_path").Value(image_path)
      .Key("num_views").Value(static_cast<uint64_t>(views.size()))
      .Key("num_observations").Value(num_observations)
      .Key("mean_reprojection_error_px").Value(mean_error)
      .Key("max_reprojection_error_px").Value(max_error);
  json.Key("bounds").BeginObject()
      .Key("min").Value(JsonArray(bounds.box.min()))
      .Key("max").Value(JsonArray(bounds.box.max()))
      .Key("explicit").Value(bounds.is_explicit)
      .Key("num_points_used").Value(bounds.num_used)
      .Key("summary").Value(bounds.Summary())
      .EndObject();
  json.Key("views").BeginArray();
  for (size_t i = 0; i < views.size(); ++i) {
    const ViewCheck& check = views[i];
    const CalibratedView& view = calibrated[i];
    std::vector<double> P_rows;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) P_rows.push_back(view.P(r, c));
    }
    json.BeginObject()
        .Key("image_id").Value(static_cast<uint64_t>(check.image_id))
        .Key("name").Value(check.name)
        .Key("width").Value(view.width)
        .Key("height").Value(view.height)
        .Key("P_row_major").Value(P_rows)
        .Key("centre").Value(JsonArray(view.centre))
        .Key("num_observations").Value(check.num_observations)
        .Key("num_behind_camera").Value(check.num_behind)
        .Key("mean_reprojection_error_px").Value(check.mean_error)
        .Key("median_reprojection_error_px").Value(check.median_error)
        .Key("max_reprojection_error_px").Value(check.max_error)
        .Key("box_corners_in_image").Value(check.box_corners_in_image)
        .Key("box_in_front").Value(check.box_in_front)
        .Key("valid_pixel_fraction").Value(check.valid_fraction)
        .EndObject();
  }
  json.EndArray().EndObject();
  return json.str();
}

int RunCalibrate(int argc, char** argv) {
  std::string workspace_path, input_path, image_path, output_path;
  bool write_undistorted = true;
  ViewReaderOptions view_options;
  BoundsRequest bounds_flags;
  OptionParser parser(
      "calibrate",
      "Turns every registered image of a COLMAP project into a calibrated view (undistorted "
      "photo, 3x4 projection), bounds the volume, checks the sparse points' reprojection through "
      "the views, and writes undistorted photos, views and a report.");
  AddWorkspaceFlags(&parser, {&workspace_path, &input_path, &image_path, &output_path});
  parser.BeginGroup("Outputs");
  parser.AddDefault("write_undistorted", &write_undistorted,
                    "write the undistorted photos and their validity masks");
  parser.AddDefault("skip_missing_images", &view_options.skip_missing_images,
                    "skip registered images whose photo is missing instead of failing");
  AddBoundsFlags(&parser, &bounds_flags);
  if (!parser.Parse(argc, argv)) return 0;

  ProjectRequest load;
  load.command = "calibrate";
  load.workspace_path = workspace_path;
  load.input_path = input_path;
  load.image_path = image_path;
  load.output_path = output_path;
  load.bounds = bounds_flags;
  load.view_options = view_options;
  load.min_images = 1;
  const LoadedProject project = LoadProject(load);
  output_path = project.output_path;
  const std::vector<CalibratedView>& views = project.views;
  const Bounds& bounds = project.bounds;
  const CalibrationReport report = CalibrateProject(project.reconstruction, views, bounds);

  std::error_code error;
  std::filesystem::create_directories(output_path, error);
  if (error) throw InputError(output_path + ": cannot create the output folder: " + error.message());
  const std::filesystem::path root(output_path);
  const std::vector<OutputPair> targets =
      write_undistorted ? PlanUndistortedOutputs(project, view_options, root) : std::vector<OutputPair>();
  // The outputs are written into a staging folder and moved into place together, report.json
  // last: an interrupted run leaves the previous set whole.
  StagedOutputs staged(output_path);
  const std::filesystem::path stage(staged.path());
  staged.Write([&] {
    WriteUndistorted(project.views, targets, root, stage);
    WriteTextFileAtomically((stage / "report.json").string(),
                            report.Json(project.model_path, project.image_path, views));
  });
  const std::string report_path = (root / "report.json").string();
  staged.MoveIntoPlace("report.json");
  std::cout << report.Table() << bounds.Summary() << "\n"
            << project.view_summary.Summary() << "\n"
            << "wrote " << report_path
            << (write_undistorted ? ", undistorted/<name> and masks/<name>.png (valid pixels)" : "")
            << "\n";
  return 0;
}

}  // namespace raycarve
