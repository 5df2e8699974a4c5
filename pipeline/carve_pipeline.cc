#include "pipeline/carve_pipeline.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include <glog/logging.h>

#include "calib/input_error.h"
#include "pipeline/output_files.h"

namespace raycarve {
namespace {

// The default resolution is lowered to what the photos resolve, but not below this: a coarser
// grid than this says the photos are too small for the volume, and the refusal says so.
constexpr int kMinLoweredResolution = 16;
// The fewest pixels a voxel spans, at the default resolution, when the box was narrowed to the
// masks' hull (CarvePipeline::CheckVolume).
constexpr double kNarrowedVoxelPixels = 3.0;

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;  // CarvePipeline::Clock

// True when `inner` is `outer` or lies inside it (both canonical).
bool Within(const fs::path& inner, const fs::path& outer) {
  const auto [outer_end, unused] = std::mismatch(outer.begin(), outer.end(), inner.begin(), inner.end());
  return outer_end == outer.end();
}

// Logs what the sparse points are used for, when anything.
void LogSurfacePointUses(const CarveOptions& options, size_t count) {
  std::vector<std::string> uses;
  if (options.auto_threshold) uses.push_back("choose the threshold");
  if (options.protect_surface_points) uses.push_back("protect their voxels");
  if (options.free_space_margin_voxels > 0.0) uses.push_back("carve their sight lines");
  if (uses.empty()) return;
  std::string joined;
  for (size_t u = 0; u < uses.size(); ++u) {
    joined += (u == 0 ? " " : (u + 1 == uses.size() ? " and " : ", ")) + uses[u];
  }
  LOG(INFO) << count << " reliable sparse points (seen by " << kMinSurfaceTrack
            << "+ photos, error <= " << kMaxSurfaceError << " px) in the volume" << joined;
}

// "; measured through ..." where the level's thresholds were (CarveOptions::threshold_seen_views).
std::string FirstPassText(const LevelStatistics& level) {
  if (level.first_pass_seconds <= 0.0) return "";
  std::ostringstream text;
  text << "; measured through a first pass carved at the tracks' threshold "
       << level.first_pass_threshold << " (" << level.first_pass_seconds << " s)";
  return text.str();
}

// Logs what the carve did beyond colouring: free space, floaters, repair, thresholds.
void LogCarve(const CarveOptions& options, const CarveStatistics& s) {
  if (s.free_space_sight_lines > 0) LOG(INFO) << s.FreeSpaceSummary();
  if (s.distant_rays > 0) {
    LOG(INFO) << "distant free space: " << s.distant_rays << " rays of distant pixels carved "
              << s.distant_carved << " voxels"
              << (s.distant_through_ground > 0
                      ? "; " + std::to_string(s.distant_through_ground) +
                            " more would have passed down through the held ground, and were not "
                            "drawn"
                      : std::string());
  }
  if (s.unsupported_components > 0) LOG(INFO) << s.FloaterSummary();
  if (s.silhouette_repair.views > 0) LOG(INFO) << s.silhouette_repair.Summary();
  for (const LevelStatistics& level : s.levels) {
    if (!options.auto_threshold) break;
    if (level.threshold_given) {
      LOG(INFO) << "level " << level.resolution << ": threshold " << level.threshold
                << " (estimated over the whole volume by the tile plan)";
    } else if (level.threshold_from_data) {
      LOG(INFO) << "level " << level.resolution << ": " << level.estimate.Summary()
                << (level.threshold_resolution > 0
                        ? " (measured at " + std::to_string(level.threshold_resolution) +
                              " voxels on the photos as they are: this level enlarges them " +
                              std::to_string(level.image_enlargement) + "x)"
                        : std::string())
                << FirstPassText(level);
    } else {
      LOG(WARNING) << "level " << level.resolution << ": only " << level.estimate.points_judged
                   << " sparse points could be judged (" << kMinThresholdPoints
                   << " needed) to choose the threshold; used " << level.threshold
                   << " (give --threshold)";
    }
  }
  LOG(INFO) << s.Summary();
}

}  // namespace

double CarvePipeline::SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

CarvePipeline::CarvePipeline(CarveRequest request, PipelineScope scope)
    : request_(std::move(request)), scope_(std::move(scope)) {}

CarvePipeline::~CarvePipeline() = default;

const CarveRun& CarvePipeline::Run() {
  LockOutputs();
  LoadViews();
  AgreeMasks();
  CheckVolume();
  PlanOutputs();
  Carve();
  MakeSurface();
  SampleCloud();
  MeasureCloud();
  WriteOutputs();
  return run_;
}

void CarvePipeline::RecordSeconds(const std::string& stage, double seconds) {
  run_.stage_seconds.emplace_back(stage, seconds);
}

void CarvePipeline::LockOutputs() {
  std::string output_path;
  paths_ = ResolveProjectPaths(ProjectRequestOf(request_, scope_.command), &output_path);
  staged_ = std::make_unique<StagedOutputs>(output_path, request_.wait_for_output);
}

void CarvePipeline::LoadViews() {
  std::string reason;
  if (!request_.options.IsValid(&reason)) {
    throw InputError("raycarve " + scope_.command + ": " + reason);
  }
  const Clock::time_point start = Clock::now();
  ProjectRequest load = ProjectRequestOf(request_, scope_.command);
  load.min_images = scope_.min_images;
  load.hold_out_every = scope_.hold_out_every;
  load.paths = paths_;
  project_ = LoadProject(load);
  // The held-out photos are kept apart, in name order; the rest are carved in load order.
  const std::set<std::string> held(project_.held_out.begin(), project_.held_out.end());
  for (CalibratedView& view : project_.views) {
    (held.count(view.name) > 0 ? held_out_ : carved_).push_back(std::move(view));
  }
  project_.views.clear();
  std::sort(held_out_.begin(), held_out_.end(),
            [](const CalibratedView& a, const CalibratedView& b) { return a.name < b.name; });
  if (carved_.size() < 2) {
    throw InputError("raycarve " + scope_.command + ": only " + std::to_string(carved_.size()) +
                     " views left to carve with" +
                     (scope_.hold_out_every > 0 ? "; raise --every" : ""));
  }
  // The sparse points as the carved views see them (the same as the project's without a hold-out).
  surface_points_ = held_out_.empty()
                        ? project_.surface_points
                        : SurfacePointsOf(project_.reconstruction, carved_, project_.bounds.box);
  run_.model_path = project_.model_path;
  run_.image_path = project_.image_path;
  run_.output_path = project_.output_path;
  run_.bounds = project_.bounds;
  run_.layout = project_.layout;
  run_.plane = project_.plane;
  run_.num_views = static_cast<int>(carved_.size());
  run_.num_missing_images = static_cast<int>(project_.view_summary.missing.size());
  run_.masks_from_files = project_.view_summary.masks_from_files;
  run_.masks_from_backdrop = project_.view_summary.masks_from_backdrop;
  run_.mask_photos = project_.view_summary.photos;
  run_.colour = project_.colour;
  for (const CalibratedView& view : carved_) run_.view_names.push_back(view.name);
  loaded_ = true;
  RecordSeconds("load_project", SecondsSince(start));
}

void CarvePipeline::DecideMasks() {
  // Minority masks would switch the carve to the masked rules and score those held-out views
  // inside them: they go, and every photo is used whole.
  const int dropped = MinorityBackdropMasks(project_.view_summary);
  if (dropped == 0) return;
  for (std::vector<CalibratedView>* views : {&carved_, &held_out_}) {
    for (CalibratedView& view : *views) view.mask.release();
  }
  run_.backdrop_masks_dropped = dropped;
  run_.masks_from_backdrop = 0;
  LOG(WARNING) << "the automatic backdrop was found in " << dropped << " of "
               << project_.view_summary.photos.size()
               << " photos only: a minority, not the capture's backdrop; carving without masks";
}

void CarvePipeline::AgreeMasks() {
  CHECK(loaded_);
  DecideMasks();
  const ViewReaderSummary& summary = project_.view_summary;
  if (!request_.agree_masks || run_.masks_from_backdrop == 0 || summary.masks_from_files > 0) {
    return;
  }
  const Clock::time_point start = Clock::now();
  MaskAgreementOptions options;
  // The voting grid: at most 64 voxels a side. Its hull only sorts pixels, and a voxel's width
  // is the margin kept inside its outline.
  options.resolution = std::min(request_.options.resolution, 64);
  options.num_threads = request_.options.num_threads;
  options.colour_tolerance = request_.view_options.background.tolerance;
  run_.mask_agreement = raycarve::AgreeMasks(project_.bounds.box, options, &carved_);
  LOG(INFO) << run_.mask_agreement.Summary(run_.view_names);
  if (run_.mask_agreement.views > 0) RecordSeconds("agree_masks", SecondsSince(start));
}

void CarvePipeline::CheckVolume() {
  CHECK(loaded_);
  DecideGround();
  DecideObjectRules();
  FindDistant();
  FindGroundPixels();
  std::string reason;
  if (!CheckCarveFits(carved_, project_.bounds.box, request_.options, &reason)) {
    throw InputError("raycarve " + scope_.command + ": " + reason);
  }
  CheckVolumeSeen(scope_.command, project_, carved_, request_.options.min_views, request_.bounds);
  // Said before the work: a voxel finer than a pixel of the photos gains little detail (the
  // photos cannot tell its neighbours apart; the carve supersamples its rays, so each voxel is
  // still judged: CarveOptions::supersample), and under half a pixel it is refused.
  const double pixel = MedianPixelFootprint(carved_, project_.bounds.box.center());
  if (!(pixel > 0.0)) return;
  const auto measure = [&] {
    const VoxelGrid grid(project_.bounds.box, request_.options.resolution);
    run_.voxel_pixels = grid.voxel_size() / pixel;
    run_.supported_resolution =
        static_cast<int>(std::floor(request_.options.resolution * run_.voxel_pixels));
  };
  measure();
  if (!request_.resolution_given && project_.bounds.around_hull) {
    // The box narrowed to the masks' hull makes the voxels finer; held out, voxels of 3-5 px
    // scored best and ones of about 2 px worse (Middlebury at 256, generated scenes: docs/
    // studies/2026-12-06-hull-box.md). No finer than 3 px, nor than the points' box gave.
    const double wide =
        VoxelGrid(project_.bounds.points_box, request_.options.resolution).voxel_size() / pixel;
    const double least = std::min(kNarrowedVoxelPixels, wide);
    if (run_.voxel_pixels < least) {
      const int resolution = std::max(
          kMinLoweredResolution,
          static_cast<int>(std::floor(request_.options.resolution * run_.voxel_pixels / least)));
      LOG(INFO) << "the box narrowed to the masks' hull: carving at --resolution " << resolution
                << " instead of the default " << request_.options.resolution
                << ", so that a voxel spans " << least << " pixels of the photos, not "
                << run_.voxel_pixels << " (give --resolution to choose)";
      run_.hull_resolution_from = request_.options.resolution;
      run_.hull_resolution = resolution;
      request_.options.resolution = resolution;
      measure();
    }
  }
  char text[96];
  std::snprintf(text, sizeof(text), "a voxel would span %.2f pixels of the photos", run_.voxel_pixels);
  if (!request_.resolution_given && run_.voxel_pixels < 1.0 && run_.supported_resolution >= kMinLoweredResolution) {
    // The default is for photos that resolve it: lowered to what these photos do.
    LOG(WARNING) << "at the default --resolution " << request_.options.resolution << " " << text
                 << " (median at the volume's centre), finer than they resolve: carving at "
                 << "--resolution " << run_.supported_resolution
                 << " instead (a voxel of one pixel; give --resolution to choose)";
    run_.resolution_lowered_from = request_.options.resolution;
    request_.options.resolution = run_.supported_resolution;
    measure();
    return;
  }
  if (request_.min_voxel_pixels > 0.0 && run_.voxel_pixels < request_.min_voxel_pixels) {
    throw InputError("raycarve " + scope_.command + ": --resolution " +
                     std::to_string(request_.options.resolution) + ": " + text +
                     " (median at the volume's centre), finer than they resolve: they support "
                     "about --resolution " + std::to_string(run_.supported_resolution) +
                     " (a voxel of one pixel). Give a lower --resolution, larger photos "
                     "(--max_image_size), or --min_voxel_pixels 0 to carve anyway");
  }
  if (run_.voxel_pixels < 1.0) {
    LOG(WARNING) << "at --resolution " << request_.options.resolution << " a voxel spans "
                 << run_.voxel_pixels << " pixels of the photos (median at the volume's "
                 << "centre): finer than they resolve. They support about --resolution "
                 << run_.supported_resolution << " (a voxel of one pixel); larger photos "
                 << "(--max_image_size) or cameras nearer the subject support more";
  } else {
    LOG(INFO) << "a voxel spans " << run_.voxel_pixels << " pixels of the photos (median at "
              << "the volume's centre); they support about --resolution "
              << run_.supported_resolution;
  }
}

void CarvePipeline::PlanOutputs() {
  CHECK(loaded_);
  const fs::path out(run_.output_path);
  // What the outputs must never land in, checked before the work starts: the masks written
  // under <output>/masks must not replace the user's.
  std::vector<std::pair<std::string, std::string>> inputs = {
      {project_.model_path, "input model"}, {project_.image_path, "photo folder"}};
  if (!request_.view_options.mask_path.empty()) {
    inputs.emplace_back(request_.view_options.mask_path, "mask folder");
  }
  mask_targets_.assign(carved_.size(), fs::path());
  bool any_mask = false;
  for (size_t v = 0; v < carved_.size(); ++v) {
    if (carved_[v].mask.empty()) continue;
    any_mask = true;
    CheckNoLinkInside(run_.output_path, "masks/" + carved_[v].name + ".png");
    mask_targets_[v] = OutputFileInside((out / "masks").string(), carved_[v].name + ".png", inputs);
  }
  // A masks folder already in the output that no earlier carve wrote (no report.json beside it)
  // is the user's: it is never written into.
  const bool ours = fs::exists(out / "report.json");
  std::error_code ignored;
  if (any_mask && !ours && fs::is_directory(out / "masks") && !fs::is_empty(out / "masks", ignored)) {
    const std::string masks = (out / "masks").string();
    throw InputError(masks + ": already holds files that raycarve did not write (no report.json "
                     "beside it); carve would write its masks there: give another --output_path "
                     "(or --mask_path " + masks + " to carve with them)");
  }
  // The output folder doubles as a COLMAP dense workspace, whose meshers read the sparse model
  // from sparse/: written there unless an input is or holds that folder, or it holds files that
  // no earlier carve wrote.
  for (const char* name : {"cloud.ply", "cloud.ply.vis", "mesh.ply", "mesh.glb", "mesh.obj",
                           "mesh.mtl", "mesh_texture.png", "preview.png", "fused.ply",
                           "fused.ply.vis", "sparse", "report.json", "report.html", "convergence.csv"}) {
    CheckNoLinkInside(run_.output_path, name);
  }
  const fs::path sparse_folder = fs::weakly_canonical(out / "sparse");
  for (const auto& [path, what] : inputs) {
    const fs::path input = fs::weakly_canonical(path);
    if (Within(input, sparse_folder) || Within(sparse_folder, input)) {
      run_.dense_sparse_skipped = "the " + what + " (" + path + ") is there";
    }
  }
  if (run_.dense_sparse_skipped.empty() && fs::is_directory(sparse_folder) &&
      !fs::is_empty(sparse_folder, ignored) && !ours) {
    run_.dense_sparse_skipped = "it holds files that raycarve did not write";
  }
  if (!run_.dense_sparse_skipped.empty()) {
    LOG(INFO) << sparse_folder.string() << ": not written (" << run_.dense_sparse_skipped
              << "); COLMAP's delaunay_mesher needs the sparse model there";
  }
  // Every output is written to a staging folder and moved into place together at the end,
  // report.json last: an interrupted run leaves the previous outputs whole. Made before the work,
  // so that an output folder that cannot be written is found at once.
  if (!staged_) staged_ = std::make_unique<StagedOutputs>(run_.output_path, request_.wait_for_output);
}

void CarvePipeline::Carve() {
  CHECK(loaded_);
  const VoxelGrid grid(project_.bounds.box, request_.options.resolution);
  const ViewReaderSummary& masks = project_.view_summary;
  if (masks.masks_from_files + masks.masks_from_backdrop == 0) {
    LOG(INFO) << "no masks (no mask files, no plain backdrop found): every photo pixel is used";
  } else {
    LOG(INFO) << (masks.masks_from_files > 0 ? "masks from " + request_.view_options.mask_path
                                             : std::string("masks from the backdrop colour"))
              << (request_.options.visual_hull ? ", with the visual hull pre-carve"
                                               : ", without the visual hull pre-carve");
  }
  LOG(INFO) << "carving a " << grid.dimensions().x() << "x" << grid.dimensions().y() << "x"
            << grid.dimensions().z() << " grid (voxel " << grid.voxel_size() << ") with "
            << carved_.size() << " views"
            << (held_out_.empty() ? "" : ", holding out " + std::to_string(held_out_.size()))
            << ", " << ConsistencyMethodToString(request_.options.consistency) << " threshold "
            << (request_.options.auto_threshold ? std::string("auto (from the sparse points)")
                                                : std::to_string(request_.options.threshold));
  LogSurfacePointUses(request_.options, surface_points_.size());
  run_.result = std::make_unique<CarveResult>(
      CarveWith(request_.options, scope_.progress, request_.progress_seconds));
  RecordCarve();
}

void CarvePipeline::RecordCarve() {
  if (scope_.progress_end) scope_.progress_end();
  LogCarve(request_.options, run_.result->statistics);
  RecordSeconds("carve_setup", run_.result->statistics.setup_seconds);
  RecordSeconds("carve", run_.result->statistics.carve_seconds);
  RecordSeconds("colour", run_.result->statistics.colour_seconds);
}

CarveResult CarvePipeline::CarveWith(CarveOptions options,
                                     const ProgressCallback& progress,
                                     double progress_interval_seconds) const {
  CHECK(loaded_);
  std::string reason;
  if (!CheckCarveFits(carved_, project_.bounds.box, options, &reason)) {
    throw InputError("raycarve " + scope_.command + ": " + CarveMethodToString(options.method) +
                     ": " + reason);
  }
  return CarveVolume(carved_, project_.bounds.box, FilledOptions(std::move(options)), progress,
                     progress_interval_seconds);
}

CarveOptions CarvePipeline::FilledOptions(CarveOptions options) const {
  if (request_.auto_spread_floor) options.spread_floor = run_.spread_floor;
  if (request_.auto_threshold_views) options.threshold_seen_views = run_.threshold_seen_views;
  options.surface_points = surface_points_;
  options.ground = run_.ground;
  options.distant_rays = distant_rays_;
  return options;
}

void CarvePipeline::MakeSurface() {
  CHECK(run_.result);
  if (request_.mesh_kind != "smooth") return;  // --mesh voxels: the voxels' faces, when written
  const Clock::time_point start = Clock::now();
  exporter::ModelMeshOptions options = request_.mesh;
  options.ground = run_.ground;
  options.remove_unseen = !CaptureIsObject();
  if (request_.level_support) {
    options.support = run_.support;
    // What the default grid over the same box levels (two of its voxels): a finer grid levels no
    // less (the sparse points place the plane no closer for it, and over a plain floor the photo
    // hull bulges a few fine voxels high).
    options.level_band = 2.0 * VoxelGrid(project_.bounds.box, CarveOptions().resolution).voxel_size();
  }
  for (const SurfacePoint& point : surface_points_) options.sparse_points.push_back(point.xyz);
  // Each step's line as it ends: the mesh stage can take longer than the carve.
  options.progress = [](const std::string& line) { LOG(INFO) << line; };
  LOG(INFO) << "meshing the surface of the solid voxels ...";
  model_ = exporter::MeshCarvedModel(*run_.result, carved_, options);
  run_.num_mesh_triangles = model_.mesh.triangles.size();
  run_.num_mesh_vertices = model_.mesh.vertices.size();
  run_.mesh_colouring = model_.colouring;
  run_.mesh_refinement = model_.refinement;
  run_.mesh_parts = model_.parts;
  run_.mesh_silhouettes = model_.silhouettes;
  run_.mesh_levelling = model_.levelling;
  run_.mesh_self_intersections = model_.self_intersections;
  run_.mesh_texture = model_.texture;
  run_.mesh_final_smoothing_mean_move = model_.final_smoothing_mean_move;
  run_.mesh_small_components_removed = model_.small_components_removed;
  run_.mesh_grid_wall_vertices = model_.grid_wall_vertices;
  run_.mesh_wall_triangles_removed = model_.wall_triangles_removed;
  run_.mesh_uncovered_triangles_removed = model_.uncovered_triangles_removed;
  run_.mesh_unseen_triangles_removed = model_.unseen_triangles_removed;
  run_.mesh_unseen_vertices_kept = model_.unseen_vertices_kept;
  run_.mesh_triangles_before_walls = model_.triangles_before_walls;
  RecordSeconds("mesh", SecondsSince(start));
}

}  // namespace raycarve
