#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <cstdio>
#include <filesystem>
#include <future>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>

#include <glog/logging.h>
#include <sys/resource.h>
#include <unistd.h>

#include "calib/atomic_file.h"
#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "calib/model_writer.h"
#include "calib/view_reader.h"
#include "carve/carver.h"
#include "export/carve_export.h"
#include "export/point_cloud_compare.h"
#include "plugin/commands.h"
#include "plugin/json_writer.h"
#include "plugin/version.h"
#include "plugin/workspace.h"

namespace raycarve {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

MaskAgreementStatistics AgreeBackdropMasks(const CarveRequest& request,
                                           const ViewReaderSummary& summary,
                                           const Eigen::AlignedBox3d& box,
                                           std::vector<CalibratedView>* views) {
  if (!request.agree_masks || summary.masks_from_backdrop == 0 || summary.masks_from_files > 0) {
    return MaskAgreementStatistics();
  }
  MaskAgreementOptions options;
  // The voting grid: at most 64 voxels a side. Its hull only sorts pixels, and a voxel's width
  // is the margin kept inside its outline.
  options.resolution = std::min(request.options.resolution, 64);
  options.num_threads = request.options.num_threads;
  options.colour_tolerance = request.view_options.background.tolerance;
  MaskAgreementStatistics statistics = AgreeMasks(box, options, views);
  std::vector<std::string> names;
  for (const CalibratedView& view : *views) names.push_back(view.name);
  LOG(INFO) << statistics.Summary(names);
  return statistics;
}

CarveRun CarveProject(const CarveRequest& request) {
  CarveRun run;
  std::string reason;
  if (!request.options.IsValid(&reason)) throw InputError("raycarve carve: " + reason);
  Clock::time_point stage = Clock::now();
  LoadedProject project =
      LoadProject("carve", request.workspace_path, request.input_path, request.image_path,
                  request.output_path, request.bounds, request.view_options, /*min_images=*/2,
                  request.model_index, ColourCalibrationModeOf(request));
  run.model_path = project.model_path;
  run.image_path = project.image_path;
  run.output_path = project.output_path;
  run.bounds = project.bounds;
  run.num_views = static_cast<int>(project.views.size());
  run.num_missing_images = static_cast<int>(project.view_summary.missing.size());
  run.masks_from_files = project.view_summary.masks_from_files;
  run.masks_from_backdrop = project.view_summary.masks_from_backdrop;
  run.mask_photos = project.view_summary.photos;
  run.colour = project.colour;
  run.stage_seconds.emplace_back("load_project", SecondsSince(stage));
  stage = Clock::now();
  run.mask_agreement =
      AgreeBackdropMasks(request, project.view_summary, run.bounds.box, &project.views);
  if (run.mask_agreement.views > 0) run.stage_seconds.emplace_back("agree_masks", SecondsSince(stage));
  for (const CalibratedView& view : project.views) run.view_names.push_back(view.name);
  const std::vector<CalibratedView>& views = project.views;

  if (!CheckCarveFits(views, run.bounds.box, request.options, &reason)) {
    throw InputError("raycarve carve: " + reason);
  }
  CheckVolumeSeen("carve", project, views, request.options.min_views, request.bounds);
  // What the outputs must never land in, checked before the work starts: the masks written
  // under <output>/masks must not replace the user's.
  std::vector<std::pair<std::string, std::string>> inputs = {
      {project.model_path, "input model"}, {project.image_path, "photo folder"}};
  if (!request.view_options.mask_path.empty()) {
    inputs.emplace_back(request.view_options.mask_path, "mask folder");
  }
  std::vector<std::filesystem::path> mask_targets(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    if (views[v].mask.empty()) continue;
    mask_targets[v] = OutputFileInside((std::filesystem::path(run.output_path) / "masks").string(),
                                       views[v].name + ".png", inputs);
  }
  // A masks folder already in the output that no earlier carve wrote (no report.json beside it)
  // is the user's: it is never written into.
  {
    const std::filesystem::path masks_folder = std::filesystem::path(run.output_path) / "masks";
    const bool ours = std::filesystem::exists(std::filesystem::path(run.output_path) / "report.json");
    bool any_mask = false;
    for (const CalibratedView& view : views) any_mask |= !view.mask.empty();
    std::error_code ignored;
    if (any_mask && !ours && std::filesystem::is_directory(masks_folder) &&
        !std::filesystem::is_empty(masks_folder, ignored)) {
      throw InputError(masks_folder.string() +
                       ": already holds files that raycarve did not write (no report.json beside "
                       "it); carve would write its masks there: give another --output_path (or "
                       "--mask_path " + masks_folder.string() + " to carve with them)");
    }
  }
  // The output folder doubles as a COLMAP dense workspace, whose meshers read the sparse model
  // from sparse/: written there unless an input is or holds that folder, or it holds files that
  // no earlier carve wrote (no report.json beside it).
  {
    namespace fs = std::filesystem;
    const fs::path sparse_folder = fs::weakly_canonical(fs::path(run.output_path) / "sparse");
    auto within = [](const fs::path& inner, const fs::path& outer) {
      const auto [outer_end, unused] =
          std::mismatch(outer.begin(), outer.end(), inner.begin(), inner.end());
      return outer_end == outer.end();
    };
    for (const auto& [path, what] : inputs) {
      const fs::path input = fs::weakly_canonical(path);
      if (within(input, sparse_folder) || within(sparse_folder, input)) {
        run.dense_sparse_skipped = "the " + what + " (" + path + ") is there";
      }
    }
    std::error_code ignored;
    if (run.dense_sparse_skipped.empty() && fs::is_directory(sparse_folder) &&
        !fs::is_empty(sparse_folder, ignored) &&
        !fs::exists(fs::path(run.output_path) / "report.json")) {
      run.dense_sparse_skipped = "it holds files that raycarve did not write";
    }
    if (!run.dense_sparse_skipped.empty()) {
      LOG(INFO) << sparse_folder.string() << ": not written (" << run.dense_sparse_skipped
                << "); COLMAP's delaunay_mesher needs the sparse model there";
    }
  }
  // Every output is written to a staging folder and moved into place together at the end,
  // report.json last: an interrupted run leaves the previous outputs whole. Made before the work,
  // so that an output folder that cannot be written is found at once.
  const std::filesystem::path final_out(run.output_path);
  StagedOutputs staged(run.output_path);
  stage = Clock::now();
  const VoxelGrid grid(run.bounds.box, request.options.resolution);
  const ViewReaderSummary& masks = project.view_summary;
  if (masks.masks_from_files + masks.masks_from_backdrop == 0) {
    LOG(INFO) << "no masks (no mask files, no plain backdrop found): every photo pixel is used";
  } else {
    LOG(INFO) << (masks.masks_from_files > 0 ? "masks from " + request.view_options.mask_path
                                             : std::string("masks from the backdrop colour"))
              << (request.options.visual_hull ? ", with the visual hull pre-carve"
                                              : ", without the visual hull pre-carve");
  }
  LOG(INFO) << "carving a " << grid.dimensions().x() << "x" << grid.dimensions().y() << "x"
            << grid.dimensions().z() << " grid (voxel " << grid.voxel_size() << ") with "
            << views.size() << " views, " << ConsistencyMethodToString(request.options.consistency)
            << " threshold "
            << (request.options.auto_threshold ? std::string("auto (from the sparse points)")
                                               : std::to_string(request.options.threshold));
  // Progress: the share of the work seen so far (evaluations against evaluations plus the
  // queue, an estimate: carving queues more) and the time left at the current rate; a bar
  // redrawn in place on a terminal, a log line otherwise.
  const bool terminal = isatty(STDERR_FILENO) != 0;
  auto progress = [terminal](const CarveProgress& p) {
    const double share =
        p.evaluated + p.queued > 0 ? static_cast<double>(p.evaluated) / (p.evaluated + p.queued) : 0.0;
    const double rate = p.seconds > 0 ? p.evaluated / p.seconds : 0.0;
    const double left = rate > 0 ? p.queued / rate : 0.0;
    const std::string level = p.levels > 1 ? "level " + std::to_string(p.level + 1) + "/" +
                                                 std::to_string(p.levels) + " "
                                           : std::string();
    if (terminal) {
      const int width = 30, filled = static_cast<int>(std::lround(share * width));
      std::fprintf(stderr, "\rcarving %s[%s%s] %3.0f%%  %.1f s, about %.1f s left  ", level.c_str(),
                   std::string(filled, '#').c_str(), std::string(width - filled, ' ').c_str(),
                   100.0 * share, p.seconds, left);
      std::fflush(stderr);
      return;
    }
    LOG(INFO) << "carving " << level << std::fixed << std::setprecision(1) << p.seconds
              << " s: evaluated " << p.evaluated << ", carved " << p.carved << ", queue "
              << p.queued << " (about " << std::lround(100.0 * share) << "% of the work seen, "
              << left << " s left at " << static_cast<int64_t>(rate) << " evaluations/s)";
  };
  CarveOptions options = request.options;
  options.surface_points = project.surface_points;
  if (options.auto_threshold || options.protect_surface_points ||
      options.free_space_margin_voxels > 0.0) {
    std::vector<std::string> uses;
    if (options.auto_threshold) uses.push_back("choose the threshold");
    if (options.protect_surface_points) uses.push_back("protect their voxels");
    if (options.free_space_margin_voxels > 0.0) uses.push_back("carve their sight lines");
    std::string joined;
    for (size_t u = 0; u < uses.size(); ++u) {
      joined += (u == 0 ? " " : (u + 1 == uses.size() ? " and " : ", ")) + uses[u];
    }
    LOG(INFO) << project.surface_points.size() << " reliable sparse points (seen by "
              << kMinSurfaceTrack << "+ photos, error <= " << kMaxSurfaceError
              << " px) in the volume" << joined;
  }
  run.result = std::make_unique<CarveResult>(
      CarveVolume(views, run.bounds.box, options, progress, request.progress_seconds));
  if (terminal) std::fprintf(stderr, "\n");
  if (run.result->statistics.free_space_sight_lines > 0) {
    LOG(INFO) << run.result->statistics.FreeSpaceSummary();
  }
  if (run.result->statistics.unsupported_components > 0) LOG(INFO) << run.result->statistics.FloaterSummary();
  if (run.result->statistics.silhouette_repair.views > 0) {
    LOG(INFO) << run.result->statistics.silhouette_repair.Summary();
  }
  for (const LevelStatistics& level : run.result->statistics.levels) {
    if (!options.auto_threshold) break;
    if (level.threshold_from_data) {
      LOG(INFO) << "level " << level.resolution << ": " << level.estimate.Summary();
    } else {
      LOG(WARNING) << "level " << level.resolution << ": only " << level.estimate.points_judged
                   << " sparse points could be judged (" << kMinThresholdPoints
                   << " needed) to choose the threshold; used " << level.threshold
                   << " (give --threshold)";
    }
  }
  run.stage_seconds.emplace_back("carve_setup", run.result->statistics.setup_seconds);
  run.stage_seconds.emplace_back("carve", run.result->statistics.carve_seconds);
  run.stage_seconds.emplace_back("colour", run.result->statistics.colour_seconds);

  stage = Clock::now();
  std::error_code error;
  const std::filesystem::path out(staged.path());
  std::vector<exporter::ColouredPoint> points;
  if (request.mesh_kind == "voxels") {
    points = exporter::SurfacePoints(*run.result, request.options.min_views);
    exporter::WritePointCloudPly(points, (out / "cloud.ply").string());
    const exporter::MeshSummary mesh =
        exporter::WriteVoxelMeshPly(*run.result, (out / "mesh.ply").string());
    run.num_mesh_triangles = mesh.num_triangles;
    run.num_mesh_vertices = mesh.num_vertices;
    run.stage_seconds.emplace_back("export", SecondsSince(stage));
  } else {
    exporter::ModelMeshOptions mesh_options = request.mesh;
    for (const SurfacePoint& point : project.surface_points) mesh_options.sparse_points.push_back(point.xyz);
    exporter::ModelMesh model = exporter::MeshCarvedModel(*run.result, views, mesh_options);
    LOG(INFO) << model.geometry.Summary();
    if (model.parts.removed > 0 || model.parts.anchored > 0) LOG(INFO) << model.parts.Summary();
    if (!model.mesh.empty()) {
      LOG(INFO) << model.refinement.Summary();
      LOG(INFO) << exporter::FinalSmoothingSummary(model, request.mesh);
      if (model.silhouettes.passes > 0) LOG(INFO) << model.silhouettes.Summary();
      LOG(INFO) << model.colouring.Summary();
    }
    run.stage_seconds.emplace_back("mesh", SecondsSince(stage));
    stage = Clock::now();
    // The mesh's checks and file on a second thread while the cloud is sampled and written: both
    // only read the mesh. (The future waits for its thread however this block is left; the
    // mesh's own failure is thrown by get().)
    auto mesh_file = [&run, &model, &out] {
      run.mesh_topology = exporter::AnalyseTopology(model.mesh);
      exporter::WriteMeshPly(model.mesh, (out / "mesh.ply").string());
    };
    std::future<void> mesh_written;
    if (ResolveNumThreads(request.options.num_threads) > 1) {
      mesh_written = std::async(std::launch::async, mesh_file);
    } else {
      mesh_file();
    }
    run.num_mesh_triangles = model.mesh.triangles.size();
    run.num_mesh_vertices = model.mesh.vertices.size();
    run.mesh_colouring = model.colouring;
    run.mesh_refinement = model.refinement;
    run.mesh_parts = model.parts;
    run.mesh_silhouettes = model.silhouettes;
    run.mesh_final_smoothing_mean_move = model.final_smoothing_mean_move;
    run.mesh_small_components_removed = model.small_components_removed;
    run.mesh_grid_wall_vertices = model.grid_wall_vertices;
    // The cloud: the mesh's surface that --cloud_min_views or more photos see, and which ones, in COLMAP's
    // visibility format (image indices: positions among the model's images in id order).
    std::vector<std::vector<uint32_t>> visibility;
    const double spacing = exporter::MedianPixelFootprint(views, run.result->volume.grid().Box().center());
    if (!model.mesh.empty() && spacing > 0.0) {
      points = exporter::SampleMeshPoints(model, spacing, request.cloud_min_views, /*seed=*/1,
                                          &visibility);
    }
    std::vector<image_t> ids;
    for (const auto& [id, image] : project.reconstruction.images) ids.push_back(id);
    std::sort(ids.begin(), ids.end());
    std::vector<uint32_t> index_of_view(views.size());
    for (size_t v = 0; v < views.size(); ++v) {
      index_of_view[v] = static_cast<uint32_t>(
          std::lower_bound(ids.begin(), ids.end(), views[v].image_id) - ids.begin());
    }
    for (std::vector<uint32_t>& seen : visibility) {
      for (uint32_t& v : seen) v = index_of_view[v];
    }
    exporter::WritePointCloudPly(points, (out / "cloud.ply").string());
    exporter::WritePointVisibility(visibility, (out / "cloud.ply.vis").string());
    if (mesh_written.valid()) mesh_written.get();
    // COLMAP's dense workspace names, for its meshers: the same files under a second name (hard
    // links; copies where the file system has none), and the sparse model they index.
    for (const char* name : {"cloud.ply", "cloud.ply.vis"}) {
      const std::filesystem::path from = out / name;
      const std::filesystem::path to = out / (std::string("fused") + (name + 5));
      std::filesystem::create_hard_link(from, to, error);
      if (error) {
        error.clear();
        std::filesystem::copy_file(from, to, std::filesystem::copy_options::overwrite_existing, error);
        if (error) throw InputError(to.string() + ": cannot write: " + error.message());
      }
    }
    if (run.dense_sparse_skipped.empty()) {
      WriteModel(project.reconstruction, (out / "sparse").string(), ModelFormat::kBinary);
    }
    run.stage_seconds.emplace_back("export", SecondsSince(stage));
  }
  run.num_cloud_points = points.size();

  // COLMAP's sparse points lie on the true surface: how far they are from the carved one.
  const Eigen::AlignedBox3d grid_box = run.result->volume.grid().Box();
  std::vector<Eigen::Vector3f> sparse, cloud;
  for (const auto& [id, point] : project.reconstruction.points3D) {
    if (grid_box.contains(point.xyz)) sparse.push_back(point.xyz.cast<float>());
  }
  for (const exporter::ColouredPoint& point : points) cloud.push_back(point.xyz);
  if (!sparse.empty() && !cloud.empty()) {
    exporter::CompareOptions compare;
    compare.threshold = 2.0 * run.result->volume.grid().voxel_size();
    compare.num_threads = request.options.num_threads;
    run.sparse = exporter::CompareClouds(cloud, sparse, compare);
    run.has_sparse = true;
  }

  // The masks used, so that a user can check them: undistorted, as the carving saw them.
  for (size_t v = 0; v < views.size(); ++v) {
    const CalibratedView& view = views[v];
    if (view.mask.empty()) continue;
    // Checked before carving; written to the same place under the staging folder.
    const std::filesystem::path mask_path = out / std::filesystem::relative(mask_targets[v], final_out);
    std::filesystem::create_directories(mask_path.parent_path(), error);
    if (error) throw InputError(mask_path.parent_path().string() + ": cannot create: " + error.message());
    WriteImageAtomically(mask_path.string(), view.mask);
  }

  std::ostringstream csv;
  csv << "seconds,carved,evaluated\n";
  for (const CurveSample& sample : run.result->statistics.curve) {
    csv << sample.seconds << "," << sample.carved << "," << sample.evaluated << "\n";
  }
  WriteTextFileAtomically((out / "convergence.csv").string(), csv.str());
  WriteTextFileAtomically((out / "report.json").string(), CarveReportJson(request, run));
  staged.MoveIntoPlace("report.json");
  return run;
}

// The process's peak resident memory so far (getrusage; Linux counts it in KiB).
double ProcessPeakMiB() {
  struct rusage usage {};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  return usage.ru_maxrss / 1024.0;
}

std::string CarveReportJson(const CarveRequest& request, const CarveRun& run) {
  const CarveStatistics& s = run.result->statistics;
  JsonWriter json;
  json.BeginObject()
      .Key("raycarve_version").Value(Version())
      .Key("commit").Value(BuildCommit())
      .Key("command_line").Value(RunCommandLine())
      .Key("start_time").Value(RunStartTime())
      .Key("model_path").Value(run.model_path)
      .Key("image_path").Value(run.image_path)
      .Key("num_views").Value(run.num_views)
      .Key("num_missing_images").Value(run.num_missing_images);
  json.Key("options").BeginObject()
      .Key("method").Value(CarveMethodToString(request.options.method))
      .Key("resolution").Value(request.options.resolution)
      .Key("consistency").Value(ConsistencyMethodToString(request.options.consistency))
      .Key("threshold").Value(request.options.auto_threshold ? std::string("auto")
                                                              : std::to_string(request.options.threshold))
      .Key("auto_threshold_quantile").Value(request.options.auto_threshold_quantile)
      .Key("pattern_threshold").Value(request.options.auto_pattern_threshold ? std::string("auto") : std::to_string(request.options.pattern_threshold))
      .Key("protect_surface_points").Value(request.options.protect_surface_points)
      .Key("free_space_margin").Value(request.options.free_space_margin_voxels)
      .Key("floater_expected_points").Value(request.options.unsupported_component_points)
      .Key("repair_silhouettes").Value(request.options.repair_silhouettes)
      .Key("adaptive_threshold").Value(request.options.adaptive_threshold)
      .Key("min_views").Value(request.options.min_views)
      .Key("min_coverage").Value(request.options.min_coverage)
      .Key("order").Value(CarveOrderToString(request.options.order))
      .Key("decision").Value(CarveDecisionToString(request.options.decision))
      .Key("lod_levels").Value(request.options.lod_levels == kAutomaticLevels
                                   ? AutomaticLevels(request.options.resolution)
                                   : request.options.lod_levels)
      .Key("lod_levels_automatic").Value(request.options.lod_levels == kAutomaticLevels)
      .Key("lod_band").Value(request.options.lod_band)
      .Key("lod_reduce_images").Value(request.options.lod_reduce_images)
      .Key("lod_threshold_scale").Value(request.options.lod_threshold_scale)
      .Key("min_component_voxels").Value(request.options.min_component_voxels)
      .Key("vis_lookup").Value(VisLookupToString(request.options.vis_lookup))
      .Key("num_threads").Value(ResolveNumThreads(request.options.num_threads))
      .Key("batch_voxels").Value(request.options.batch_voxels)
      .Key("incremental_statistics").Value(request.options.incremental_statistics)
      .Key("max_memory_gib").Value(request.options.max_memory_gib)
      .Key("max_image_size").Value(request.view_options.max_image_size)
      .Key("mask_path").Value(request.view_options.mask_path)
      .Key("background").Value(request.background)
      .Key("masks_from_files").Value(run.masks_from_files)
      .Key("masks_from_backdrop").Value(run.masks_from_backdrop)
      .Key("background_tolerance").Value(request.view_options.background.tolerance)
      .Key("mask_graph_cut").Value(request.view_options.background.refine)
      .Key("visual_hull").Value(request.options.visual_hull)
      .EndObject();
  json.Key("masks").BeginArray();
  for (const PhotoMaskInfo& photo : run.mask_photos) {
    json.BeginObject()
        .Key("name").Value(photo.name)
        .Key("source").Value(photo.source)
        .Key("object_share").Value(photo.object_share);
    if (request.background == "auto" && request.view_options.mask_path.empty()) {
      json.Key("backdrop_found").Value(photo.backdrop.found)
          .Key("border_explained").Value(photo.backdrop.explained);
      json.Key("backdrop_colours").BeginArray();
      for (size_t c = 0; c < photo.backdrop.colours.size(); ++c) {
        json.BeginObject()
            .Key("rgb").Value(JsonArray(photo.backdrop.colours[c]))
            .Key("border_share").Value(photo.backdrop.shares[c])
            .EndObject();
      }
      json.EndArray();
      json.Key("object_colours_on_border").BeginArray();
      for (const Eigen::Vector3d& colour : photo.backdrop.object_colours) {
        json.Value(JsonArray(colour));
      }
      json.EndArray();
      json.Key("object_border_share").Value(photo.backdrop.object_border_share);
      json.Key("frame_px").Value(std::vector<double>{
          static_cast<double>(photo.backdrop.frame[0]), static_cast<double>(photo.backdrop.frame[1]),
          static_cast<double>(photo.backdrop.frame[2]), static_cast<double>(photo.backdrop.frame[3])});
      json.Key("sparse_point_seeds").Value(photo.mask.seeds)
          .Key("graph_cut").Value(photo.mask.refined)
          .Key("regions_restored_by_seeds").Value(photo.mask.regions_restored)
          .Key("cut_to_volume").Value(photo.mask.cut_to_box);
    }
    const auto at = std::find(run.view_names.begin(), run.view_names.end(), photo.name);
    if (run.mask_agreement.views > 0 && at != run.view_names.end()) {
      const size_t v = static_cast<size_t>(at - run.view_names.begin());
      json.Key("agreement_added_pixels").Value(run.mask_agreement.added[v]);
    }
    json.EndObject();
  }
  json.EndArray();
  {
    const MaskAgreementStatistics& agreement = run.mask_agreement;
    const double before = std::max<int64_t>(1, agreement.TotalObjectBefore());
    json.Key("mask_agreement").BeginObject()
        .Key("enabled").Value(request.agree_masks)
        .Key("views").Value(agreement.views)
        .Key("hull_voxels").Value(agreement.hull_voxels)
        .Key("added_share").Value(agreement.views > 0 ? agreement.TotalAdded() / before : 0.0)
        .Key("seconds").Value(agreement.seconds)
        .EndObject();
  }
  if (ColourCalibrationModeOf(request) != ColourCalibrationMode::kOff) {
    json.Key("colour_calibration").BeginObject()
        .Key("mode").Value(request.colour_calibration)
        .Key("applied").Value(run.colour.applied)
        .Key("points_used").Value(run.colour.points_used)
        .Key("observations_used").Value(run.colour.observations_used)
        .Key("spread_before").Value(run.colour.spread_before)
        .Key("spread_after").Value(run.colour.spread_after);
    json.Key("photos").BeginArray();
    for (const ColourCorrection& correction : run.colour.corrections) {
      json.BeginObject()
          .Key("name").Value(correction.name)
          .Key("gain").Value(JsonArray(correction.gain))
          .Key("offset").Value(JsonArray(correction.offset))
          .Key("observations").Value(correction.observations)
          .EndObject();
    }
    json.EndArray();
    json.EndObject();
  }
  json.Key("bounds").BeginObject()
      .Key("min").Value(JsonArray(run.bounds.box.min()))
      .Key("max").Value(JsonArray(run.bounds.box.max()))
      .Key("explicit").Value(run.bounds.is_explicit)
      .EndObject();
  json.Key("statistics").BeginObject()
      .Key("visibility").Value(s.visibility)
      .Key("grid").Value(std::vector<double>{static_cast<double>(s.dimensions.x()),
                                              static_cast<double>(s.dimensions.y()),
                                              static_cast<double>(s.dimensions.z())})
      .Key("voxel_size").Value(s.voxel_size)
      .Key("num_voxels").Value(s.num_voxels)
      .Key("views_with_masks").Value(s.views_with_masks)
      .Key("silhouette_repair").BeginObject()
          .Key("views").Value(s.silhouette_repair.views)
          .Key("object_pixels").Value(s.silhouette_repair.object_pixels)
          .Key("lost_pixels").Value(s.silhouette_repair.lost_pixels)
          .Key("restored_voxels").Value(s.silhouette_repair.restored_voxels)
          .Key("bridging_voxels").Value(s.silhouette_repair.bridging_voxels)
          .Key("outside_hull_pixels").Value(s.silhouette_repair.outside_hull_pixels)
          .Key("seconds").Value(s.silhouette_repair.seconds)
          .EndObject()
      .Key("visual_hull_carved").Value(s.visual_hull_carved)
      .Key("free_space").BeginObject()
          .Key("margin_voxels").Value(request.options.free_space_margin_voxels)
          .Key("sight_lines").Value(s.free_space_sight_lines)
          .Key("voxels").Value(s.free_space_carved)
          .Key("voxels_first_level").Value(s.free_space_level0_carved)
          .Key("seconds").Value(s.free_space_seconds)
          .EndObject()
      .Key("component_carved").Value(s.component_carved)
      .Key("floaters").BeginObject()
          .Key("pieces").Value(s.unsupported_components)
          .Key("voxels").Value(s.unsupported_component_carved)
          .Key("largest_expected_points").Value(s.unsupported_largest_expected)
          .EndObject()
      .Key("visual_hull_seconds").Value(s.visual_hull_seconds)
      .Key("initial_surface").Value(s.initial_surface)
      .Key("carved").Value(s.carved)
      .Key("evaluated").Value(s.evaluated)
      .Key("passes").Value(s.passes)
      .Key("threads").Value(s.threads)
      .Key("parallel_seconds").Value(s.parallel_seconds)
      .Key("parallel_runs").Value(s.parallel_runs)
      .Key("inline_runs").Value(s.inline_runs)
      .Key("thread_work_seconds").Value(s.thread_work_seconds)
      .Key("reprojection_error_before").Value(s.reprojection_error_before)
      .Key("reprojection_error_after").Value(s.reprojection_error_after)
      .Key("final_solid").Value(s.final_solid)
      .Key("final_surface").Value(s.final_surface)
      .Key("visible_surface").Value(s.visible_surface)
      .Key("convergence_seconds").Value(s.carve_seconds)
      .Key("peak_memory_bytes").Value(static_cast<uint64_t>(s.peak_memory_bytes))
      .Key("process_peak_resident_mib").Value(ProcessPeakMiB())
      .EndObject();
  json.Key("levels").BeginArray();
  for (const LevelStatistics& level : s.levels) {
    json.BeginObject()
        .Key("resolution").Value(level.resolution)
        .Key("grid").Value(std::vector<double>{static_cast<double>(level.dimensions.x()),
                                                static_cast<double>(level.dimensions.y()),
                                                static_cast<double>(level.dimensions.z())})
        .Key("image_factor").Value(level.image_factor)
        .Key("free_space_carved").Value(level.free_space_carved)
        .Key("threshold").Value(level.threshold);
    const bool patterns = request.options.consistency == ConsistencyMethod::kPatchCorrelation;
    if (patterns) json.Key("pattern_threshold").Value(level.pattern_threshold);
    if (request.options.auto_threshold || (patterns && request.options.auto_pattern_threshold)) {
      const ThresholdEstimate& e = level.estimate;
      std::vector<double> surface, front;
      for (int q = 0; q <= 20; ++q) {
        surface.push_back(ThresholdEstimate::Quantile(e.surface_errors, q / 20.0));
        front.push_back(ThresholdEstimate::Quantile(e.front_errors, q / 20.0));
      }
      json.Key("threshold_estimate").BeginObject()
          .Key("from_data").Value(level.threshold_from_data)
          .Key("quantile").Value(e.quantile)
          .Key("points_in_grid").Value(e.points_in_grid)
          .Key("points_judged").Value(e.points_judged)
          .Key("surface_error_quantiles_0_to_1_by_0_05").Value(surface)
          .Key("front_offset_voxels").Value(ThresholdEstimate::kFrontOffsetVoxels)
          .Key("front_voxels").Value(static_cast<uint64_t>(e.front_errors.size()))
          .Key("front_error_quantiles_0_to_1_by_0_05").Value(front)
          .Key("front_share_above_threshold").Value(e.FrontCarved())
          .EndObject();
    }
    json.Key("protected_kept").Value(level.protected_kept)
        .Key("start_solid").Value(level.start_solid)
        .Key("carved").Value(level.carved)
        .Key("evaluated").Value(level.evaluated)
        .Key("final_solid").Value(level.final_solid)
        .Key("seconds").Value(level.seconds)
        .Key("setup_seconds").Value(level.setup_seconds)
        .EndObject();
  }
  json.EndArray();
  if (run.has_sparse) {
    const double voxel = run.result->volume.grid().voxel_size();
    json.Key("sparse_points").BeginObject()
        .Key("count").Value(static_cast<uint64_t>(run.sparse.num_reconstruction))
        .Key("within_2_voxels").Value(run.sparse.precision)
        .Key("distance_90_percent_voxels").Value(run.sparse.accuracy / voxel)
        .Key("mean_distance_voxels").Value(run.sparse.mean_reconstruction_to_reference / voxel)
        .Key("reliable_ones_kept_by_known_surface").Value(request.options.protect_surface_points)
        .EndObject();
  }
  json.Key("stage_seconds").BeginObject();
  for (const auto& [name, seconds] : run.stage_seconds) json.Key(name).Value(seconds);
  json.EndObject();
  json.Key("outputs").BeginObject()
      .Key("cloud").Value("cloud.ply")
      .Key("cloud_visibility").Value(request.mesh_kind == "smooth" ? "cloud.ply.vis" : "")
      .Key("dense_workspace").Value(request.mesh_kind == "smooth" && run.dense_sparse_skipped.empty())
      .Key("dense_workspace_note")
      .Value(request.mesh_kind != "smooth"
                 ? std::string("--mesh voxels: no visibility, no dense workspace")
                 : run.dense_sparse_skipped.empty()
                       ? std::string("fused.ply and fused.ply.vis (cloud.ply and cloud.ply.vis "
                                     "under COLMAP's names) and the sparse model in sparse/")
                       : "sparse/ not written: " + run.dense_sparse_skipped)
      .Key("cloud_points").Value(static_cast<uint64_t>(run.num_cloud_points))
      .Key("cloud_min_views").Value(request.mesh_kind == "smooth" ? request.cloud_min_views
                                                                  : request.options.min_views)
      .Key("mesh").Value("mesh.ply")
      .Key("mesh_kind").Value(request.mesh_kind)
      .Key("mesh_triangles").Value(static_cast<uint64_t>(run.num_mesh_triangles))
      .Key("mesh_vertices").Value(static_cast<uint64_t>(run.num_mesh_vertices))
      .Key("convergence").Value("convergence.csv")
      .EndObject();
  if (request.mesh_kind == "smooth") {
    const exporter::MeshTopology& t = run.mesh_topology;
    const exporter::MeshColouringSummary& c = run.mesh_colouring;
    json.Key("mesh").BeginObject()
        .Key("closed_manifold").Value(t.IsClosedManifold())
        .Key("components").Value(static_cast<int64_t>(t.components))
        .Key("small_components_removed").Value(run.mesh_small_components_removed)
        .Key("grid_wall_vertices").Value(run.mesh_grid_wall_vertices)
        .Key("boundary_edges").Value(static_cast<int64_t>(t.boundary_edges))
        .Key("non_manifold_edges").Value(static_cast<int64_t>(t.non_manifold_edges))
        .Key("non_manifold_vertices").Value(static_cast<int64_t>(t.non_manifold_vertices))
        .Key("edge_pixels").Value(request.mesh.edge_pixels)
        .Key("max_faces").Value(static_cast<int64_t>(request.mesh.max_triangles))
        .Key("smoothing_iterations").Value(request.mesh.smoothing_iterations)
        .Key("refine_passes").Value(request.mesh.refine_passes)
        .Key("refine_converged_voxels").Value(request.mesh.refine_converged_voxels)
        .Key("refinement_passes").Value(run.mesh_refinement.passes)
        .Key("refinement_last_mean_abs_offset_voxels")
        .Value(run.mesh_refinement.last_mean_abs_offset / run.result->volume.grid().voxel_size())
        .Key("refinement_vertices_moved").Value(run.mesh_refinement.moved)
        .Key("refinement_mean_abs_offset_voxels")
        .Value(run.mesh_refinement.mean_abs_offset / run.result->volume.grid().voxel_size())
        .Key("refinement_mean_pinned").Value(run.mesh_refinement.mean_pinned)
        .Key("final_smoothing_iterations").Value(request.mesh.final_smoothing_iterations)
        .Key("final_smoothing_mean_move_voxels")
        .Value(run.mesh_final_smoothing_mean_move / run.result->volume.grid().voxel_size())
        .Key("part_min_views").Value(request.mesh.part_min_views)
        .Key("parts_before").Value(run.mesh_parts.parts)
        .Key("parts_removed_unneeded").Value(run.mesh_parts.removed)
        .Key("vertices_removed_unneeded").Value(run.mesh_parts.removed_vertices)
        .Key("parts_kept_for_sparse_points").Value(run.mesh_parts.anchored)
        .Key("silhouette_passes").Value(run.mesh_silhouettes.passes)
        .Key("silhouette_outline_vertices").Value(run.mesh_silhouettes.outline_vertices)
        .Key("silhouette_pulled_vertices").Value(run.mesh_silhouettes.pulled_vertices)
        .Key("silhouette_beyond_masks_px_first").Value(run.mesh_silhouettes.mean_outside_pixels_first)
        .Key("silhouette_beyond_masks_px_last").Value(run.mesh_silhouettes.mean_outside_pixels_last)
        .Key("silhouette_mean_move_voxels")
        .Value(run.mesh_silhouettes.mean_move / run.result->volume.grid().voxel_size())
        .Key("vertices_coloured_from_photos").Value(c.from_photos)
        .Key("vertices_coloured_from_neighbours").Value(c.from_neighbours)
        .Key("vertices_uncoloured").Value(c.uncoloured)
        .Key("share_seen").Value(c.SeenShare())
        .Key("mean_photos_per_vertex").Value(c.mean_views)
        .EndObject();
  }
  json.EndObject();
  return json.str();
}

void AddCarveFlags(OptionParser* parser, CarveRequest* request, CarveFlagText* text) {
  text->consistency = ConsistencyMethodToString(request->options.consistency);
  text->vis_lookup = VisLookupToString(request->options.vis_lookup);
  text->method = CarveMethodToString(request->options.method);
  text->order = CarveOrderToString(request->options.order);
  text->decision = CarveDecisionToString(request->options.decision);
  parser->AddDefault("workspace_path", &request->workspace_path,
                     "COLMAP project (sparse/0 or sparse or dense/sparse, with images/)");
  parser->AddDefault("input_path", &request->input_path, "model folder, overriding the workspace's");
  parser->AddDefault("model_index", &request->model_index,
                     "with several models in sparse/ (from colmap mapper): use sparse/<index>; "
                     "-1: the one with the most registered images");
  parser->AddDefault("image_path", &request->image_path, "photo folder, overriding the workspace's");
  parser->AddDefault("output_path", &request->output_path,
                     "output folder (default <workspace>/raycarve)");
  parser->AddDefault("method", &text->method,
                     "visibility: ray casting (the seed paper), or its baselines GVC (item "
                     "buffers, passes) and GVC-LDI (layered depth images)",
                     {"ray", "gvc", "gvc_ldi"});
  parser->AddDefault("resolution", &request->options.resolution,
                     "voxels along the longest axis of the volume");
  parser->AddDefault("consistency", &text->consistency,
                     "photo-consistency test: the seed paper's mean colours, Seitz and Dyer's "
                     "standard deviation, or ncc (mean colours, and where the photos see texture "
                     "the normalised cross-correlation of the voxel's patch in every view)",
                     {"mean_colour", "standard_deviation", "ncc"});
  parser->AddDefault("pattern_threshold", &text->pattern_threshold,
                     "with --consistency ncc: carve a textured voxel when 1 - NCC of its "
                     "patterns exceeds this (0-2); auto: per level from the sparse points, by "
                     "--threshold auto's rule, also when --threshold is a number (0.5 where too "
                     "few can be judged)");
  parser->AddDefault("threshold", &text->threshold,
                     "largest consistent error, RGB units 0-255; auto: per level of detail from "
                     "the reliable sparse points: with masks the --auto_threshold_quantile of "
                     "their voxels' errors, without masks the weighted equal error against the "
                     "voxels just in front (30 where fewer than 20 can be judged)");
  parser->AddDefault("auto_threshold_quantile", &request->options.auto_threshold_quantile,
                     "with --threshold auto and masks: the share of the voxels on sparse points "
                     "that the threshold keeps");
  parser->AddDefault("protect_surface_points", &request->options.protect_surface_points,
                     "never carve a voxel holding a reliable sparse point (track of 2 or more "
                     "photos, error <= 1 px) by colour: stops carving that runs away");
  parser->AddDefault("free_space_margin", &request->options.free_space_margin_voxels,
                     "carve the sight lines from each photo to the reliable sparse points it saw "
                     "(empty space), stopping this many voxels short of the point; 0: off");
  parser->AddDefault("floater_expected_points", &request->options.unsupported_component_points,
                     "carve a piece of the model (26-connected, under a quarter of the largest) "
                     "that holds no reliable sparse point where the points' density on the model "
                     "predicts at least this many; 0: keep every piece");
  parser->AddDefault("repair_silhouettes", &request->options.repair_silhouettes,
                     "with masks: after carving, give each photo's object pixels back the model "
                     "that carving took from their rays (a membrane across holes the masks "
                     "contradict)");
  parser->AddDefault("adaptive_threshold", &request->options.adaptive_threshold,
                     "raise the threshold by this times the voxel's within-view colour spread "
                     "(texture edges); 0: a fixed threshold");
  parser->AddDefault("min_views", &request->options.min_views,
                     "views a voxel must be seen by to be judged");
  parser->AddDefault("min_coverage", &request->options.min_coverage,
                     "judge a voxel only when --min_views views each see at least this share of "
                     "its projected outline (not through a small hole); 0: any pixel counts");
  parser->AddDefault("vis_lookup", &text->vis_lookup,
                     "how Vis(V) finds its rays: the paper's footprint scan, or per-voxel ray "
                     "lists (same result, more memory)",
                     {"footprint", "ray_lists"});
  parser->AddDefault("order", &text->order,
                     "order of the voxels to judge: first in first out, or most visible pixels "
                     "first",
                     {"fifo", "visible_pixels"});
  parser->AddDefault("decision", &text->decision,
                     "carve when the error exceeds --threshold, or when carving lowers the "
                     "reprojection error of the pixels involved (ray casting only)",
                     {"threshold", "reprojection"});
  parser->AddDefault("lod_levels", &request->options.lod_levels,
                     "levels of detail: carve at resolution / 2^(L-1) first, then refine (the "
                     "resolution must be divisible by 2^(L-1)); 1: no levels; 0: as many as "
                     "keep the coarsest level at 64 voxels or more (128: 2, 256: 3)");
  parser->AddDefault("lod_band", &request->options.lod_band,
                     "voxels put back around what survived a coarse level before refining");
  parser->AddDefault("lod_reduce_images", &request->options.lod_reduce_images,
                     "coarse levels carve photos reduced by the level's voxel scale (block "
                     "means): a voxel covers about as many pixels at every level");
  parser->AddDefault("lod_threshold_scale", &request->options.lod_threshold_scale,
                     "a level whose voxels are 2^k times the final ones judges with threshold x "
                     "this^k (coarse voxels straddle more texture; only the final level uses "
                     "--threshold as given)");
  parser->AddDefault("min_component_voxels", &request->options.min_component_voxels,
                     "after carving, carve every connected piece of fewer solid voxels than this "
                     "(specks in empty space) and carry on carving behind them; 0: keep all");
  parser->AddDefault("colour_calibration", &request->colour_calibration,
                     "estimate a gain and offset per photo and channel from the sparse points' "
                     "colours (Ceres, robust) and correct the photos before carving: 1 always, "
                     "auto where the correction at least halves the points' colour spread across "
                     "photos (different exposures), 0 never",
                     {"auto", "1", "0", "true", "false"});
  parser->AddDefault("num_threads", &request->options.num_threads,
                     "threads for ray casting and colouring (-1: one per core, at most one per "
                     "photo); the carving is identical for any count");
  parser->AddDefault("batch_voxels", &request->options.batch_voxels,
                     "voxels judged at once (on every thread) against the rays as they stand, "
                     "then carved together; 1: the seed paper's one voxel at a time");
  parser->AddDefault("incremental_statistics", &request->options.incremental_statistics,
                     "ray casting: keep per-voxel colour sums as rays arrive instead of gathering "
                     "Vis(V)'s pixels at every evaluation (same carving)");
  parser->AddDefault("max_memory_gib", &request->options.max_memory_gib,
                     "refuse grids whose carving structures would need more (GiB)");
  parser->AddDefault("skip_missing_images", &request->view_options.skip_missing_images,
                     "skip registered images whose photo is missing instead of failing");
  parser->AddDefault("max_image_size", &request->view_options.max_image_size,
                     "photos longer than this on their longer side are scaled down to it, their "
                     "cameras with them, as COLMAP's --max_image_size (about 14 bytes a pixel are "
                     "held while carving: 200 photos at 2400 take ~12 GB); <= 0: full size");
  parser->AddDefault("mask_path", &request->view_options.mask_path,
                     "folder of object masks (<photo name>.png, non-zero = object): background "
                     "pixels are left out, and the silhouettes pre-carve the volume");
  parser->AddDefault("background_colour", &text->background,
                     "without --mask_path, masks from a plain backdrop: auto (a photo whose border "
                     "is one to five plain colours, behind an optional frame, gets a mask; natural "
                     "scenes are left as they are), none, or R,G,B");
  parser->AddDefault("background_tolerance", &request->view_options.background.tolerance,
                     "RGB distance from the backdrop colour beyond which a pixel is object");
  parser->AddDefault("mask_graph_cut", &request->view_options.background.refine,
                     "auto masks: refine the colour rule by a graph cut (GrabCut) seeded with the "
                     "sparse points; 0: the colour rule alone");
  parser->AddDefault("agree_masks", &request->agree_masks,
                     "masks from the backdrop: where a photo's mask leaves out what 2+ others "
                     "agree is object (well inside their hull's outline, in the colour they see "
                     "there), it becomes object");
  parser->AddDefault("visual_hull", &request->options.visual_hull,
                     "with masks, carve the silhouettes' visual hull before colouring");
  parser->AddDefault("mesh", &request->mesh_kind,
                     "mesh.ply: a smooth welded surface coloured from the photos, or the voxels' "
                     "faces in their mean colours",
                     {"smooth", "voxels"});
  parser->AddDefault("mesh_edge_pixels", &request->mesh.edge_pixels,
                     "smooth mesh: split edges longer than this many photo pixels, so colours "
                     "keep the photos' detail (0: no splitting)");
  parser->AddDefault("cloud_min_views", &request->cloud_min_views,
                     "smooth mesh: cloud.ply keeps the surface that at least this many photos see "
                     "(COLMAP's fusion asks 5 by default); the mesh keeps everything");
  parser->AddDefault("mesh_max_faces", &request->mesh_max_faces,
                     "smooth mesh: at most this many triangles, by decimation (0: no budget)");
  parser->AddDefault("mesh_smoothing_iterations", &request->mesh.smoothing_iterations,
                     "smooth mesh: windowed-sinc smoothing passes (0: the stair-stepped surface)");
  parser->AddDefault("mesh_refine_passes", &request->mesh.refine_passes,
                     "smooth mesh: at most this many passes moving vertices along their normals "
                     "(up to a voxel each) to where the photos agree best (0: none)");
  parser->AddDefault("mesh_final_smoothing", &request->mesh.final_smoothing_iterations,
                     "smooth mesh: after refinement, windowed-sinc passes that smooth each vertex "
                     "by the share the photos leave open (none where a clear cost minimum pins "
                     "it; all over plain surfaces and where fewer than two photos see it); 0: "
                     "none");
  parser->AddDefault("mesh_part_min_views", &request->mesh.part_min_views,
                     "smooth mesh: a part of the mesh (a connected piece) stays only where this "
                     "many masked photos need it (half or more of what it covers in the photo is "
                     "object that no other part covers); the largest part always stays; 0: keep "
                     "every part");
  parser->AddDefault("mesh_silhouette_passes", &request->mesh.silhouette_passes,
                     "smooth mesh: after the final smoothing, passes pulling the outline's "
                     "vertices that stand beyond the masks in onto the masks' edges (the median "
                     "over the photos; at most a voxel a pass); 0: none");
  parser->AddDefault("mesh_refine_converged", &request->mesh.refine_converged_voxels,
                     "smooth mesh: the refinement stops after a pass that moves the vertices by "
                     "less than this many voxels on average (0: run every pass)");
  AddBoundsFlags(parser, &request->bounds);
}

void ApplyCarveFlags(const CarveFlagText& text, CarveRequest* request) {
  if (text.pattern_threshold == "auto") {
    request->options.auto_pattern_threshold = true;
    request->options.pattern_threshold = kFallbackPatternThreshold;
  } else {
    char* end = nullptr;
    const double value = std::strtod(text.pattern_threshold.c_str(), &end);
    if (text.pattern_threshold.empty() || end == nullptr || *end != '\0' ||
        !(value >= 0.0 && value <= 2.0)) {
      throw InputError("--pattern_threshold: must be a number in [0, 2] or auto, got '" +
                       text.pattern_threshold + "'");
    }
    request->options.auto_pattern_threshold = false;
    request->options.pattern_threshold = value;
  }
  if (text.threshold == "auto") {
    request->options.auto_threshold = true;
    request->options.threshold = kFallbackThreshold;
  } else {
    char* end = nullptr;
    const double value = std::strtod(text.threshold.c_str(), &end);
    if (text.threshold.empty() || end == nullptr || *end != '\0' || !std::isfinite(value) ||
        value < 0.0) {
      throw InputError("--threshold: threshold must be a finite number >= 0 (0: no voxel is "
                       "consistent) or auto, got '" + text.threshold + "'");
    }
    request->options.auto_threshold = false;
    request->options.threshold = value;
  }
  ConsistencyMethodFromString(text.consistency, &request->options.consistency);
  VisLookupFromString(text.vis_lookup, &request->options.vis_lookup);
  CarveMethodFromString(text.method, &request->options.method);
  CarveOrderFromString(text.order, &request->options.order);
  CarveDecisionFromString(text.decision, &request->options.decision);
  request->view_options.background.mode =
      ParseBackground(text.background, &request->view_options.background.colour);
  request->background = text.background;
  std::string reason;
  if (!request->view_options.background.IsValid(&reason)) throw InputError(reason);
  if (!request->options.IsValid(&reason)) throw InputError(reason);
  if (request->options.num_threads != -1 &&
      (request->options.num_threads < 1 || request->options.num_threads > 1024)) {
    throw InputError("--num_threads: must be -1 (every core) or 1 to 1024, got " +
                     std::to_string(request->options.num_threads));
  }
  if (request->mesh_max_faces > static_cast<uint64_t>(std::numeric_limits<int32_t>::max())) {
    throw InputError("--mesh_max_faces: at most " +
                     std::to_string(std::numeric_limits<int32_t>::max()) + ", got " +
                     std::to_string(request->mesh_max_faces));
  }
  request->mesh.max_triangles = static_cast<int64_t>(request->mesh_max_faces);
  if (request->cloud_min_views < 1) {
    throw InputError("--cloud_min_views: must be >= 1, got " + std::to_string(request->cloud_min_views));
  }
  // --num_threads holds for every stage: loading the photos, carving, meshing, colouring, and
  // the libraries' own parallel loops.
  request->mesh.num_threads = request->options.num_threads;
  request->view_options.num_threads = request->options.num_threads;
  exporter::SetLibraryThreads(request->options.num_threads);
  request->mesh.min_views = request->options.min_views;
  // The mesh drops what is smaller than the iso-surface of the smallest speck the carve keeps
  // (a cube of min_component_voxels voxels: 6 faces of n^(2/3) vertices).
  request->mesh.min_component_vertices = static_cast<int64_t>(
      std::ceil(6.0 * std::pow(static_cast<double>(std::max<int64_t>(request->options.min_component_voxels, 0)), 2.0 / 3.0)));
  if (!request->mesh.IsValid(&reason)) throw InputError("--mesh_*: " + reason);
}

// One line on where the masks came from: per source the count, and for backdrop masks the
// colours found (those of the first such photo), frames and the median object share.
std::string MaskSummary(const std::vector<PhotoMaskInfo>& photos) {
  std::map<std::string, int> count;
  std::vector<double> shares;
  const PhotoMaskInfo* first_backdrop = nullptr;
  int framed = 0, no_backdrop = 0;
  for (const PhotoMaskInfo& photo : photos) {
    ++count[photo.source];
    if (photo.source != "none") shares.push_back(photo.object_share);
    if (photo.source == "backdrop") {
      if (first_backdrop == nullptr) first_backdrop = &photo;
      framed += std::max({photo.backdrop.frame[0], photo.backdrop.frame[1],
                          photo.backdrop.frame[2], photo.backdrop.frame[3]}) > 0;
    }
    no_backdrop += photo.source == "none" && photo.backdrop.explained > 0.0;
  }
  std::ostringstream text;
  const char* separator = "";
  for (const auto& [source, n] : count) {
    text << separator << n << (source == "file"       ? " from mask files"
                               : source == "backdrop" ? " from the backdrop"
                               : source == "colour"   ? " from the given backdrop colour"
                                                      : " without a mask");
    separator = ", ";
  }
  if (first_backdrop != nullptr) {
    text << "; backdrop of the first: " << first_backdrop->backdrop.Summary();
    if (framed > 0) text << "; " << framed << " photos with a frame";
  }
  if (no_backdrop > 0) text << "; " << no_backdrop << " photos show no plain backdrop (natural scene?)";
  if (!shares.empty()) {
    std::nth_element(shares.begin(), shares.begin() + shares.size() / 2, shares.end());
    text << "; object " << std::lround(100.0 * shares[shares.size() / 2])
         << "% of a photo (median)";
  }
  return text.str();
}

int RunCarve(int argc, char** argv) {
  CarveRequest request;
  CarveFlagText text;
  OptionParser parser(
      "carve",
      "Carves a coloured voxel model from a COLMAP project by incremental voxel colouring with "
      "ray-cast visibility, and writes cloud.ply (points with normals and colours, laid out like "
      "COLMAP's fused.ply, sampled on the mesh about one point per photo pixel) with "
      "cloud.ply.vis (the images that see each point, COLMAP's fused.ply.vis format), mesh.ply "
      "(a smooth welded surface coloured from the photos), report.json and convergence.csv; "
      "fused.ply, fused.ply.vis and sparse/ make the output folder a COLMAP dense workspace for "
      "its meshers.");
  AddCarveFlags(&parser, &request, &text);
  if (!parser.Parse(argc, argv)) return 0;
  ApplyCarveFlags(text, &request);

  const CarveRun run = CarveProject(request);
  const CarveStatistics& s = run.result->statistics;
  std::string sparse_line = "none in the volume";
  if (run.has_sparse) {
    char text[240];
    std::snprintf(text, sizeof(text), "%zu in the volume: %.1f%% within 2 voxels of the cloud, 90%% within %.2f voxels%s",
                  run.sparse.num_reconstruction, 100.0 * run.sparse.precision,
                  run.sparse.accuracy / s.voxel_size,
                  request.options.protect_surface_points
                      ? "\n                  (known surface keeps the reliable ones' voxels: no independent measure)"
                      : "");
    sparse_line = text;
  }
  const std::string mask_line = MaskSummary(run.mask_photos);
  std::string silhouette_line;
  if (s.silhouette_repair.views > 0) {
    silhouette_line = "  silhouettes     " + std::to_string(s.silhouette_repair.lost_pixels) +
                      " object pixels of the masks had lost the model to carving; " +
                      std::to_string(s.silhouette_repair.restored_voxels) + " voxels restored\n";
  }
  size_t judged_voxels = 0;
  for (const ColouredVoxel& voxel : run.result->surface) {
    judged_voxels += voxel.num_views >= request.options.min_views;
  }
  std::string level_line;
  for (const LevelStatistics& level : s.levels) {
    char text[96];
    if (request.options.consistency == ConsistencyMethod::kPatchCorrelation) {
      std::snprintf(text, sizeof(text), "%s%d voxels at threshold %.3g, pattern %.2f",
                    level_line.empty() ? "" : "; ", level.resolution, level.threshold,
                    level.pattern_threshold);
    } else {
      std::snprintf(text, sizeof(text), "%s%d voxels at threshold %.3g",
                    level_line.empty() ? "" : ", ", level.resolution, level.threshold);
    }
    level_line += text;
  }
  std::string floater_text;
  if (s.unsupported_components > 0) {
    floater_text = ", " + std::to_string(s.unsupported_component_carved) + " in " +
                   std::to_string(s.unsupported_components) + " floaters without sparse points";
  }
  std::printf(
      "\ncarved %s\n"
      "  grid            %d x %d x %d voxels of %.4g (%lld voxels)\n"
      "  carved          %lld voxels (%lld by the visual hull of %d masked views, %lld by the "
      "sparse points' sight lines, %lld in specks%s), %lld evaluations\n"
      "  levels          %zu (%s)\n"
      "  convergence     %.2f s (+ %.2f s set-up) on %s, carving structures' peak %.1f MiB\n"
      "  process memory  %.1f MiB at its peak (resident: photos, views, grid, mesh)\n"
      "  surface         %lld voxels, %lld seen by the photos, %zu by %d or more\n"
      "  sparse points   %s\n"
      "  masks           %s\n"
      "%s"
      "  outputs         %s/cloud.ply (%zu points, seen by %d+ photos), mesh.ply (%zu triangles),\n"
      "                  report.json, convergence.csv\n"
      "  open with       meshlab %s/mesh.ply   (or CloudCompare, Open3D, colmap gui)\n",
      run.model_path.c_str(), s.dimensions.x(), s.dimensions.y(), s.dimensions.z(), s.voxel_size,
      static_cast<long long>(s.num_voxels), static_cast<long long>(s.carved),
      static_cast<long long>(s.visual_hull_carved), s.views_with_masks,
      static_cast<long long>(s.free_space_level0_carved),
      static_cast<long long>(s.component_carved), floater_text.c_str(),
      static_cast<long long>(s.evaluated),
      s.levels.size(), level_line.c_str(), s.carve_seconds, s.setup_seconds,
      s.ThreadsText().c_str(), s.peak_memory_bytes / (1024.0 * 1024.0), ProcessPeakMiB(), static_cast<long long>(s.final_surface),
      static_cast<long long>(s.visible_surface), judged_voxels, request.options.min_views,
      sparse_line.c_str(), mask_line.c_str(), silhouette_line.c_str(), run.output_path.c_str(),
      run.num_cloud_points,
      request.mesh_kind == "smooth" ? request.cloud_min_views : request.options.min_views,
      run.num_mesh_triangles, run.output_path.c_str());
  if (s.final_solid == 0 || s.visible_surface == 0) {
    std::printf(
        "  warning         the carve kept nothing %s: the files are valid but empty. Try a higher "
        "--threshold (or auto), --protect_surface_points 1, and check that the photos see the "
        "volume (--bbox, the masks in %s/masks)\n",
        s.final_solid == 0 ? "(every voxel was found inconsistent or unseen)"
                           : "that a photo sees",
        run.output_path.c_str());
  }
  if (request.mesh_kind == "smooth" && run.num_cloud_points > 0) {
    // COLMAP's Poisson trim of 10 suits its own fused clouds of megapixel photos; a cloud of one
    // point per pixel of smaller photos is thinner, and trim 10 leaves nothing (measured on the
    // demo: densities 3.9-9.3, 0 vertices at trim 10, 556k at 5).
    std::printf("  COLMAP mesher   colmap poisson_mesher --input_path %s/fused.ply --output_path "
                "%s/poisson.ply --PoissonMeshing.trim 5\n",
                run.output_path.c_str(), run.output_path.c_str());
    if (run.dense_sparse_skipped.empty()) {
      std::printf("                  (the output is a COLMAP dense workspace: fused.ply, fused.ply.vis, "
                  "sparse/; colmap delaunay_mesher --input_path %s --input_type dense, where "
                  "COLMAP has CGAL)\n",
                  run.output_path.c_str());
    } else {
      std::printf("                  (sparse/ not written: %s)\n", run.dense_sparse_skipped.c_str());
    }
  }
  if (request.mesh_kind == "smooth" && run.num_mesh_triangles > 0) {
    const exporter::MeshColouringSummary& c = run.mesh_colouring;
    std::printf("  mesh            %zu triangles, %zu vertices, %lld component%s, %s;\n"
                "                  %.1f%% of its vertices coloured from %d+ photos (%.1f each), "
                "the rest from seen neighbours\n",
                run.num_mesh_triangles, run.num_mesh_vertices,
                static_cast<long long>(run.mesh_topology.components),
                run.mesh_topology.components == 1 ? "" : "s",
                run.mesh_topology.IsClosedManifold() ? "closed and 2-manifold"
                                                     : "NOT closed 2-manifold (see report.json)",
                100.0 * c.SeenShare(), request.mesh.min_views, c.mean_views);
    if (run.mesh_grid_wall_vertices > 0) {
      std::printf("                  %lld vertices on the volume box's walls, where the box cuts the "
                  "scene: in the mesh, left out of the cloud\n",
                  static_cast<long long>(run.mesh_grid_wall_vertices));
    }
  }
  return 0;
}

}  // namespace raycarve
