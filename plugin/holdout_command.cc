#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <set>

#include <glog/logging.h>
#include <opencv2/imgproc.hpp>

#include "calib/atomic_file.h"
#include "calib/input_error.h"
#include "carve/carver.h"
#include "export/carve_export.h"
#include "export/holdout_score.h"
#include "export/mesh_renderer.h"
#include "export/point_cloud_compare.h"
#include "export/point_renderer.h"
#include "export/volume_renderer.h"
#include "pipeline/carve_pipeline.h"
#include "pipeline/carve_report.h"
#include "plugin/carve_flags.h"
#include "plugin/commands.h"
#include "plugin/option_parser.h"
#include "pipeline/json_writer.h"
#include "pipeline/output_files.h"
#include "pipeline/run_info.h"

namespace raycarve {

namespace {

// The held-out views' masks replaced by those in `mask_path` (<photo name>.png, as --mask_path),
// undistorted as the carve's are: to score automatic masks against exact ones.
void ReplaceScoringMasks(const CarvePipeline& pipeline,
                         const std::string& mask_path,
                         std::vector<CalibratedView>* held_out) {
  const LoadedProject& project = pipeline.project();
  std::set<std::string> names;
  for (const CalibratedView& view : *held_out) names.insert(view.name);
  Reconstruction held_out_model = project.reconstruction;
  held_out_model.images.clear();
  for (const auto& [id, image] : project.reconstruction.images) {
    if (names.count(image.name) > 0) held_out_model.images.emplace(id, image);
  }
  ViewReaderOptions options = pipeline.request().view_options;
  options.mask_path = mask_path;
  std::vector<CalibratedView> scored =
      ReadCalibratedViews(held_out_model, project.image_path, options, nullptr);
  std::map<std::string, cv::Mat> mask_of;
  for (CalibratedView& view : scored) mask_of[view.name] = view.mask;
  for (CalibratedView& view : *held_out) view.mask = mask_of.at(view.name);
  LOG(INFO) << "held-out views scored against the masks in " << mask_path;
}

// Someone else's cloud (--model without faces) as splats of `splat_size` (0: 1.5 x its median
// neighbour spacing), returned in *point_size.
std::vector<exporter::ColouredPoint> CloudOf(const exporter::TriangleMesh& cloud,
                                             const std::string& path,
                                             double splat_size,
                                             double* point_size) {
  std::vector<exporter::ColouredPoint> points;
  std::vector<Eigen::Vector3f> xyz;
  for (size_t i = 0; i < cloud.vertices.size(); ++i) {
    exporter::ColouredPoint point;
    point.xyz = cloud.vertices[i];
    point.rgb = cloud.colours[i];
    points.push_back(point);
    xyz.push_back(point.xyz);
  }
  *point_size = splat_size > 0.0 ? splat_size : 1.5 * exporter::MedianNeighbourSpacing(xyz);
  if (!(*point_size > 0.0)) {
    throw InputError(path + ": cannot tell the cloud's spacing; give --point_size");
  }
  LOG(INFO) << path << ": " << points.size() << " points, drawn as splats of " << *point_size;
  return points;
}

// Each level's threshold (and pattern threshold with ncc), for the report.
std::string ThresholdsText(const CarveOptions& options, const CarveStatistics& statistics) {
  std::string thresholds;
  for (const LevelStatistics& level : statistics.levels) {
    char text[64];
    if (options.consistency == ConsistencyMethod::kPatchCorrelation) {
      std::snprintf(text, sizeof(text), "%s%d: %.1f / %.2f", thresholds.empty() ? "" : ", ",
                    level.resolution, level.threshold, level.pattern_threshold);
    } else {
      std::snprintf(text, sizeof(text), "%s%d: %.1f", thresholds.empty() ? "" : ", ",
                    level.resolution, level.threshold);
    }
    thresholds += text;
  }
  return thresholds;
}

}  // namespace

int RunHoldout(int argc, char** argv) {
  CarveRequest request;
  CarveFlagText text;
  int every = 4;
  std::string render = "mesh";
  std::string other_path;
  std::string score_mask_path;
  double splat_size = 0.0;
  OptionParser parser(
      "holdout",
      "Held-out evaluation: carves the project without every k-th view, renders the carved model "
      "into the left-out views, and reports PSNR (over the rendered and the true silhouette where "
      "there is a mask, else over the whole photo) and silhouette IoU; writes photo | render | "
      "error images to <output>/holdout/ and holdout.json.");
  AddCarveFlags(&parser, &request, &text);
  parser.BeginGroup("Held-out photos");
  parser.AddDefault("every", &every, "leave out views 1, 1 + k, 1 + 2k, ... (k >= 2)");
  parser.AddDefault("render", &render,
                    "how the model is drawn: the smooth mesh coloured from the training photos "
                    "(what carve writes as mesh.ply), the carved volume (a ray per pixel to the "
                    "first solid voxel, in its colour) or the cloud's points as square splats",
                    {"mesh", "volume", "splats"});
  parser.AddDefault("model", &other_path,
                    "score this PLY mesh or cloud instead of carving (COLMAP's fused.ply, another "
                    "tool's mesh with vertex colours), on the same held-out views");
  parser.AddDefault("point_size", &splat_size,
                    "splat side (world units) for a cloud given by --model (0: 1.5 x the cloud's "
                    "median neighbour spacing)");
  parser.AddDefault("score_mask_path", &score_mask_path,
                    "score the held-out views against these masks (<photo name>.png, as "
                    "--mask_path) instead of the masks the carve uses: to compare automatic "
                    "masks with exact ones on the same footing");
  parser.SetBasicOptions({"workspace_path", "output_path", "every", "render", "model",
                          "score_mask_path", "resolution", "mask_path", "num_threads"});
  parser.AddExample("raycarve holdout --workspace_path P",
                    "carve without every 4th photo at carve's defaults; score the mesh in those photos");
  parser.AddExample("raycarve holdout --workspace_path P --model P/dense/fused.ply",
                    "score another model (COLMAP's fused cloud) on the same held-out photos");
  if (!parser.Parse(argc, argv)) return 0;
  ApplyCarveFlags(text, &request);
  if (every < 2) throw InputError("raycarve holdout: --every must be at least 2");

  PipelineScope scope;
  scope.command = "holdout";
  scope.min_images = 3;
  // Every k-th image in name order is held out; its observations leave the sparse points before
  // the bounds, the colour calibration and the surface evidence are taken from them.
  scope.hold_out_every = every;
  CarvePipeline pipeline(request, scope);
  pipeline.LoadViews();
  const LoadedProject& project = pipeline.project();
  const std::vector<CalibratedView>& training = pipeline.carved_views();
  std::vector<CalibratedView> held_out = pipeline.held_out_views();
  if (!score_mask_path.empty()) ReplaceScoringMasks(pipeline, score_mask_path, &held_out);
  // Block PSNR's block: about a voxel of the grid the carve uses (or would use).
  const VoxelGrid grid(project.bounds.box, request.options.resolution);
  const CarveResult* result = nullptr;
  std::vector<exporter::ColouredPoint> points;
  double point_size = grid.voxel_size();
  exporter::ModelMesh model;
  std::string thresholds;
  if (!other_path.empty()) {
    model.mesh = exporter::ReadMeshOrCloudPly(other_path);
    if (model.mesh.triangles.empty()) {
      render = "splats";
      points = CloudOf(model.mesh, other_path, splat_size, &point_size);
    } else {
      render = "mesh";
      LOG(INFO) << other_path << ": " << model.mesh.triangles.size() << " triangles";
    }
  } else {
    // The same stages as carve's, on the training views: their masks agree among themselves
    // (the held-out photos' are scored as made), the model coloured from them only.
    pipeline.AgreeMasks();
    pipeline.CheckVolume();
    pipeline.Carve();
    result = pipeline.run().result.get();
    thresholds = ThresholdsText(request.options, result->statistics);
    points = exporter::SurfacePoints(*result, request.options.min_views);
    point_size = result->volume.grid().voxel_size();
    if (render == "mesh") {
      pipeline.MakeSurface();
      model = pipeline.model();
    }
  }

  // Written as a set, as carve's outputs: staged, then moved into place with holdout.json last.
  const std::filesystem::path final_out = std::filesystem::path(project.output_path) / "holdout";
  StagedOutputs staged(final_out.string());
  const std::filesystem::path out(staged.path());
  JsonWriter json;
  json.BeginObject();
  WriteRunIdentity(json);
  json.Key("model_path").Value(project.model_path)
      .Key("every").Value(every)
      .Key("score_mask_path").Value(score_mask_path)
      .Key("training_views").Value(static_cast<uint64_t>(training.size()))
      .Key("cloud_points").Value(static_cast<uint64_t>(points.size()))
      .Key("render").Value(render)
      .Key("mesh_triangles").Value(static_cast<uint64_t>(model.mesh.triangles.size()))
      .Key("mesh_seconds")
      .Value(model.geometry.seconds + model.parts.seconds + model.refinement.seconds +
             model.silhouettes.seconds + model.colouring.seconds)
      .Key("model").Value(other_path.empty() ? std::string("carved") : other_path)
      .Key("carve").Value(result ? result->statistics.Summary() : std::string())
      .Key("evaluated").Value(result ? result->statistics.evaluated : int64_t{0})
      .Key("threads").Value(result ? result->statistics.threads : 0)
      .Key("convergence_seconds").Value(result ? result->statistics.carve_seconds : 0.0)
      .Key("thresholds").Value(thresholds)
      .Key("surface_points").Value(static_cast<uint64_t>(other_path.empty() ? pipeline.surface_points().size() : 0));
  json.Key("views").BeginArray();
  double psnr_sum = 0.0, iou_sum = 0.0, volume_psnr_sum = 0.0, volume_iou_sum = 0.0;
  int iou_count = 0;
  // What one colour per voxel could carry at best: the photo against its own means over blocks
  // of about a voxel's projected width (at the volume's centre).
  const Eigen::Vector3d volume_centre = grid.Box().center();
  const double block_size = grid.voxel_size();
  double block_psnr_sum = 0.0;
  std::printf("%-24s %10s %12s %10s %16s\n", "held-out view", "PSNR dB", "scored px", "sil. IoU",
              "block PSNR dB");
  for (const CalibratedView& view : held_out) {
    int uncoloured = 0;
    exporter::Rendering rendering;
    if (render == "volume") {
      exporter::VolumeRendering drawn = exporter::RenderVolume(result->volume, result->surface, view);
      uncoloured = drawn.uncoloured_pixels;
      rendering = std::move(drawn);
    } else if (render == "mesh") {
      rendering = exporter::RenderMesh(model.mesh, view);
    } else {
      rendering = exporter::RenderPoints(points, view, point_size);
    }
    const exporter::HoldoutScore score = exporter::ScoreRendering(rendering, view);
    // The mesh is scored beside the voxel volume it was made from, drawn into the same view.
    exporter::HoldoutScore volume_score = score;
    if (render == "mesh" && result) {
      volume_score = exporter::ScoreRendering(
          exporter::RenderVolume(result->volume, result->surface, view), view);
    }
    volume_psnr_sum += volume_score.psnr;
    volume_iou_sum += std::max(0.0, volume_score.silhouette_iou);
    const double focal = 0.5 * (view.K(0, 0) + view.K(1, 1));
    const int block = std::max(
        1, static_cast<int>(std::lround(focal * block_size / view.Depth(volume_centre))));
    const double block_psnr = exporter::BlockMeanPsnr(view, block);
    block_psnr_sum += block_psnr;
    psnr_sum += score.psnr;
    if (score.silhouette_iou >= 0.0) {
      iou_sum += score.silhouette_iou;
      ++iou_count;
    }
    std::printf("%-24s %10.2f %12d %10.3f %10.2f (%dx%d)\n", view.name.c_str(), score.psnr,
                score.scored_pixels, score.silhouette_iou, block_psnr, block, block);
    json.BeginObject()
        .Key("name").Value(view.name)
        .Key("psnr_db").Value(score.psnr)
        .Key("scored_pixels").Value(score.scored_pixels)
        .Key("silhouette_iou").Value(score.silhouette_iou)
        .Key("uncoloured_pixels").Value(uncoloured)
        .Key("block_pixels").Value(block)
        .Key("block_mean_psnr_db").Value(block_psnr)
        .Key("volume_psnr_db").Value(volume_score.psnr)
        .Key("volume_silhouette_iou").Value(volume_score.silhouette_iou)
        .EndObject();
    cv::Mat bgr;
    cv::cvtColor(exporter::SideBySide(rendering, view), bgr, cv::COLOR_RGB2BGR);
    const std::string path = (out / (std::filesystem::path(view.name).stem().string() + ".png")).string();
    WriteImageAtomically(path, bgr);
  }
  json.EndArray();
  const double mean_psnr = psnr_sum / held_out.size();
  const double mean_iou = iou_count > 0 ? iou_sum / iou_count : -1.0;
  const double mean_block_psnr = block_psnr_sum / held_out.size();
  const double mean_volume_psnr = volume_psnr_sum / held_out.size();
  const double mean_volume_iou = iou_count > 0 ? volume_iou_sum / iou_count : -1.0;
  json.Key("mean_psnr_db").Value(mean_psnr).Key("mean_silhouette_iou").Value(mean_iou)
      .Key("mean_block_mean_psnr_db").Value(mean_block_psnr)
      .Key("mean_volume_psnr_db").Value(mean_volume_psnr)
      .Key("mean_volume_silhouette_iou").Value(mean_volume_iou).EndObject();
  if (render == "mesh" && result) {
    // The model that was scored, for a look at it.
    exporter::WriteMeshPly(model.mesh, (out / "mesh.ply").string());
  }
  WriteTextFileAtomically((out / "holdout.json").string(), json.str());
  staged.MoveIntoPlace("holdout.json");
  const std::string report = (final_out / "holdout.json").string();
  std::printf("mean over %zu held-out views: PSNR %.2f dB, silhouette IoU %s\n"
              "block PSNR: each photo against its own means over blocks a voxel wide, on the "
              "object: about the most one colour per voxel can score (mean %.2f dB)\n"
              "wrote %s, %s/<view>.png (photo | render | error x4)%s\n",
              held_out.size(), mean_psnr,
              iou_count > 0 ? std::to_string(mean_iou).c_str() : "n/a (no masks)", mean_block_psnr,
              report.c_str(), final_out.string().c_str(),
              render == "mesh" && result ? " and mesh.ply" : "");
  if (render == "mesh" && result) {
    std::printf("the voxel volume drawn into the same views: PSNR %.2f dB, silhouette IoU %s "
                "(the mesh: %+.2f dB)\n",
                mean_volume_psnr,
                iou_count > 0 ? std::to_string(mean_volume_iou).c_str() : "n/a (no masks)",
                mean_psnr - mean_volume_psnr);
  }
  return 0;
}

}  // namespace raycarve
