#include "pipeline/holdout_evaluation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include <glog/logging.h>
#include <opencv2/imgproc.hpp>

#include "calib/atomic_file.h"
#include "calib/input_error.h"
#include "export/mesh_file_reader.h"
#include "export/carve_export.h"
#include "export/mesh_renderer.h"
#include "export/point_cloud_compare.h"
#include "export/point_renderer.h"
#include "export/volume_renderer.h"
#include "pipeline/carve_pipeline.h"
#include "pipeline/carve_report.h"
#include "pipeline/json_writer.h"
#include "pipeline/output_files.h"

namespace raycarve {
namespace {

// What is drawn into the held-out photos: the carve's mesh or volume, its surface voxels as
// splats, or someone else's model.
struct ScoredModel {
  const CarveResult* result = nullptr;  // null: a given model
  std::vector<exporter::ColouredPoint> points;
  double point_size = 0.0;
  exporter::ModelMesh model;
  std::string thresholds;
  // Per held-out name, the sparse points it saw (LoadedProject::held_out_points).
  const std::map<std::string, std::vector<Eigen::Vector3d>>* held_out_points = nullptr;
};

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

// Someone else's model (options.model_path): a mesh drawn as it is, a cloud as splats.
void ReadGivenModel(const HoldoutOptions& options, ScoredModel* scored, std::string* render) {
  scored->model.mesh = exporter::ReadModelFile(options.model_path);
  const exporter::TriangleMesh& mesh = scored->model.mesh;
  if (!mesh.triangles.empty()) {
    *render = "mesh";
    LOG(INFO) << options.model_path << ": " << mesh.triangles.size() << " triangles";
    return;
  }
  *render = "splats";
  std::vector<Eigen::Vector3f> xyz;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    exporter::ColouredPoint point;
    point.xyz = mesh.vertices[i];
    point.rgb = mesh.colours[i];
    scored->points.push_back(point);
    xyz.push_back(point.xyz);
  }
  scored->point_size =
      options.point_size > 0.0 ? options.point_size : 1.5 * exporter::MedianNeighbourSpacing(xyz);
  if (!(scored->point_size > 0.0)) {
    throw InputError(options.model_path + ": cannot tell the cloud's spacing; give --point_size");
  }
  LOG(INFO) << options.model_path << ": " << scored->points.size()
            << " points, drawn as splats of " << scored->point_size;
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

// How far from a sparse point's depth the model may be drawn and still agree with it, in voxels.
constexpr double kSparseDepthToleranceVoxels = 2.0;
double SparseDepthTolerance(const VoxelGrid& grid) {
  return kSparseDepthToleranceVoxels * grid.voxel_size();
}

// The model drawn into `view` and scored; the photo | render | error image written to `out`.
HeldOutViewScore ScoreView(const ScoredModel& scored,
                           const std::string& render,
                           const VoxelGrid& grid,
                           const CalibratedView& view,
                           const std::filesystem::path& out) {
  HeldOutViewScore result;
  result.name = view.name;
  const CarveResult* carve = scored.result;
  exporter::Rendering rendering;
  if (render == "volume") {
    exporter::VolumeRendering drawn = exporter::RenderVolume(carve->volume, carve->surface, view);
    result.uncoloured_pixels = drawn.uncoloured_pixels;
    rendering = std::move(drawn);
  } else if (render == "mesh") {
    rendering = exporter::RenderMesh(scored.model.mesh, view);
  } else {
    rendering = exporter::RenderPoints(scored.points, view, scored.point_size);
  }
  result.score = exporter::ScoreRendering(rendering, view);
  const auto seen = scored.held_out_points->find(view.name);
  if (seen != scored.held_out_points->end()) {
    std::vector<Eigen::Vector3d> inside;
    for (const Eigen::Vector3d& point : seen->second) {
      if (grid.Box().contains(point)) inside.push_back(point);
    }
    result.sparse_depth = exporter::MeasureSparseDepth(
        rendering, view, inside, SparseDepthTolerance(grid), &result.sparse_points);
  }
  // The mesh is scored beside the voxel volume it was made from, drawn into the same view.
  result.volume_score = result.score;
  if (render == "mesh" && carve != nullptr) {
    result.volume_score =
        exporter::ScoreRendering(exporter::RenderVolume(carve->volume, carve->surface, view), view);
  }
  // What one colour per voxel could carry at best: the photo against its own means over blocks
  // of about a voxel's projected width (at the volume's centre).
  const double focal = 0.5 * (view.K(0, 0) + view.K(1, 1));
  result.block = std::max(
      1, static_cast<int>(std::lround(focal * grid.voxel_size() / view.Depth(grid.Box().center()))));
  result.block_psnr = exporter::BlockMeanPsnr(view, result.block);
  cv::Mat bgr;
  cv::cvtColor(exporter::SideBySide(rendering, view), bgr, cv::COLOR_RGB2BGR);
  WriteImageAtomically((out / (std::filesystem::path(view.name).stem().string() + ".png")).string(), bgr);
  return result;
}

void AverageScores(HoldoutEvaluation* evaluation) {
  double psnr = 0.0, ssim = 0.0, iou = 0.0, block = 0.0, volume_psnr = 0.0, volume_iou = 0.0;
  for (const HeldOutViewScore& view : evaluation->views) {
    evaluation->sparse_depth.points += view.sparse_depth.points;
    evaluation->sparse_depth.at_depth += view.sparse_depth.at_depth;
    evaluation->sparse_depth.hidden += view.sparse_depth.hidden;
    evaluation->sparse_depth.behind += view.sparse_depth.behind;
    psnr += view.score.psnr;
    ssim += view.score.ssim;
    block += view.block_psnr;
    volume_psnr += view.volume_score.psnr;
    volume_iou += std::max(0.0, view.volume_score.silhouette_iou);
    if (view.score.silhouette_iou >= 0.0) {
      iou += view.score.silhouette_iou;
      ++evaluation->iou_views;
    }
  }
  const double n = static_cast<double>(evaluation->views.size());
  evaluation->mean_psnr = psnr / n;
  evaluation->mean_ssim = ssim / n;
  evaluation->mean_block_psnr = block / n;
  evaluation->mean_volume_psnr = volume_psnr / n;
  evaluation->mean_iou = evaluation->iou_views > 0 ? iou / evaluation->iou_views : -1.0;
  evaluation->mean_volume_iou = evaluation->iou_views > 0 ? volume_iou / evaluation->iou_views : -1.0;
}

// A name as one CSV field: quoted where it holds a comma, a quote or a line break.
std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

// Every held-out view's sparse points with the model's verdict, one line each: where the model
// and the points disagree, to be looked at (or checked against a truth, samples/truth_sparse_depth).
std::string SparseDepthCsv(const HoldoutEvaluation& evaluation) {
  std::string csv = "view,x,y,z,depth,drawn_depth,verdict\n";
  char line[512];
  for (const HeldOutViewScore& view : evaluation.views) {
    for (const exporter::SparsePointDepth& p : view.sparse_points) {
      std::snprintf(line, sizeof(line), ",%.9g,%.9g,%.9g,%.9g,%.9g,%s\n", p.point.x(), p.point.y(),
                    p.point.z(), p.depth, p.drawn_depth,
                    exporter::SparseDepthVerdictName(p.verdict));
      csv += CsvField(view.name) + line;
    }
  }
  return csv;
}

std::string HoldoutJson(const HoldoutOptions& options,
                        const CarvePipeline& pipeline,
                        const ScoredModel& scored,
                        const HoldoutEvaluation& evaluation) {
  const exporter::ModelMesh& model = scored.model;
  const CarveResult* result = scored.result;
  JsonWriter json;
  json.BeginObject();
  WriteRunIdentity(json);
  json.Key("model_path").Value(pipeline.project().model_path)
      .Key("every").Value(options.every)
      .Key("score_mask_path").Value(options.score_mask_path)
      .Key("training_views").Value(static_cast<uint64_t>(pipeline.carved_views().size()))
      .Key("cloud_points").Value(static_cast<uint64_t>(scored.points.size()))
      .Key("render").Value(evaluation.render)
      .Key("mesh_triangles").Value(static_cast<uint64_t>(model.mesh.triangles.size()))
      .Key("mesh_seconds")
      .Value(model.geometry.seconds + model.parts.seconds + model.refinement.seconds +
             model.silhouettes.seconds + model.colouring.seconds)
      .Key("model").Value(options.model_path.empty() ? std::string("carved") : options.model_path)
      .Key("carve").Value(result ? result->statistics.Summary() : std::string())
      .Key("evaluated").Value(result ? result->statistics.evaluated : int64_t{0})
      .Key("threads").Value(result ? result->statistics.threads : 0)
      .Key("convergence_seconds").Value(result ? result->statistics.carve_seconds : 0.0)
      .Key("thresholds").Value(scored.thresholds)
      .Key("surface_points")
      .Value(static_cast<uint64_t>(result ? pipeline.surface_points().size() : 0));
  json.Key("views").BeginArray();
  for (const HeldOutViewScore& view : evaluation.views) {
    json.BeginObject()
        .Key("name").Value(view.name)
        .Key("psnr_db").Value(view.score.psnr)
        .Key("ssim").Value(view.score.ssim)
        .Key("scored_pixels").Value(view.score.scored_pixels)
        .Key("silhouette_iou").Value(view.score.silhouette_iou)
        .Key("uncoloured_pixels").Value(view.uncoloured_pixels)
        .Key("block_pixels").Value(view.block)
        .Key("block_mean_psnr_db").Value(view.block_psnr)
        .Key("volume_psnr_db").Value(view.volume_score.psnr)
        .Key("volume_silhouette_iou").Value(view.volume_score.silhouette_iou)
        .Key("sparse_points").Value(view.sparse_depth.points)
        .Key("sparse_at_depth_share").Value(view.sparse_depth.AtDepthShare())
        .Key("sparse_hidden_share").Value(view.sparse_depth.HiddenShare())
        .Key("sparse_behind_share").Value(view.sparse_depth.BehindShare())
        .Key("sparse_undrawn_share").Value(view.sparse_depth.UndrawnShare())
        .EndObject();
  }
  json.EndArray();
  json.Key("mean_psnr_db").Value(evaluation.mean_psnr)
      .Key("mean_ssim").Value(evaluation.mean_ssim)
      .Key("mean_silhouette_iou").Value(evaluation.mean_iou)
      .Key("mean_block_mean_psnr_db").Value(evaluation.mean_block_psnr)
      .Key("mean_volume_psnr_db").Value(evaluation.mean_volume_psnr)
      .Key("mean_volume_silhouette_iou").Value(evaluation.mean_volume_iou)
      .Key("sparse_points").Value(evaluation.sparse_depth.points)
      .Key("sparse_at_depth_share").Value(evaluation.sparse_depth.AtDepthShare())
      .Key("sparse_hidden_share").Value(evaluation.sparse_depth.HiddenShare())
      .Key("sparse_behind_share").Value(evaluation.sparse_depth.BehindShare())
      .Key("sparse_undrawn_share").Value(evaluation.sparse_depth.UndrawnShare())
      .Key("sparse_depth_tolerance_voxels").Value(kSparseDepthToleranceVoxels)
      .Key("sparse_depth_tolerance").Value(evaluation.sparse_depth_tolerance)
      .EndObject();
  return json.str();
}

}  // namespace

HoldoutEvaluation EvaluateHeldOutViews(const CarveRequest& request, const HoldoutOptions& options) {
  if (options.every < 2) throw InputError("raycarve holdout: --every must be at least 2");
  PipelineScope scope;
  scope.command = "holdout";
  scope.min_images = 3;
  // Every k-th image in name order is held out; its observations leave the sparse points before
  // the bounds, the colour calibration and the surface evidence are taken from them.
  scope.hold_out_every = options.every;
  CarvePipeline pipeline(request, scope);
  pipeline.LoadViews();
  // The images are named after the held-out photos: <output>/holdout must be a folder of its own.
  const std::string output_path = pipeline.project().output_path;
  const std::filesystem::path final_out = std::filesystem::path(output_path) / "holdout";
  CheckNoLinkInside(output_path, "holdout");
  CheckOutputFileOutside(final_out.string(), pipeline.project().image_path, "photo folder");
  CheckOutputFileOutside(final_out.string(), pipeline.project().model_path, "input model");
  // Written as a set, as carve's outputs: staged, then moved into place with holdout.json last.
  // Made before the carve, so that a folder that cannot be written is found at once.
  StagedOutputs staged(final_out.string(), request.wait_for_output);
  const std::filesystem::path out(staged.path());
  std::vector<CalibratedView> held_out = pipeline.held_out_views();
  if (!options.score_mask_path.empty()) ReplaceScoringMasks(pipeline, options.score_mask_path, &held_out);
  // Block PSNR's block: about a voxel of the grid the carve uses (or would use).
  const VoxelGrid grid(pipeline.project().bounds.box, request.options.resolution);
  HoldoutEvaluation evaluation;
  evaluation.render = options.render;
  evaluation.sparse_depth_tolerance = SparseDepthTolerance(grid);
  ScoredModel scored;
  scored.point_size = grid.voxel_size();
  scored.held_out_points = &pipeline.project().held_out_points;
  if (!options.model_path.empty()) {
    ReadGivenModel(options, &scored, &evaluation.render);
  } else {
    // The same stages as carve's, on the training views: their masks agree among themselves
    // (the held-out photos' are scored as made), the model coloured from them only.
    pipeline.AgreeMasks();
    pipeline.CheckVolume();
    pipeline.Carve();
    scored.result = pipeline.run().result.get();
    scored.thresholds = ThresholdsText(request.options, scored.result->statistics);
    scored.points = exporter::SurfacePoints(*scored.result, request.options.min_views);
    scored.point_size = scored.result->volume.grid().voxel_size();
    if (options.render == "mesh") {
      pipeline.MakeSurface();
      scored.model = pipeline.model();
    }
    evaluation.carved = true;
  }
  staged.Write([&] {
    for (const CalibratedView& view : held_out) {
      evaluation.views.push_back(ScoreView(scored, evaluation.render, grid, view, out));
    }
    AverageScores(&evaluation);
    if (evaluation.render == "mesh" && evaluation.carved) {
      // The model that was scored, for a look at it.
      exporter::WriteMeshPly(scored.model.mesh, (out / "mesh.ply").string());
      evaluation.wrote_mesh = true;
    }
    WriteTextFileAtomically((out / "sparse_depth.csv").string(), SparseDepthCsv(evaluation));
    WriteTextFileAtomically((out / "holdout.json").string(),
                            HoldoutJson(options, pipeline, scored, evaluation));
  });
  staged.MoveIntoPlace("holdout.json");
  evaluation.output_folder = final_out.string();
  return evaluation;
}

}  // namespace raycarve
