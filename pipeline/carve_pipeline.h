#pragma once

#include <chrono>
#include <filesystem>
#include <functional>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "calib/atomic_file.h"
#include "calib/distant_pixels.h"
#include "carve/carver.h"
#include "carve/tiling.h"
#include "export/supporting_plane.h"
#include "carve/mask_agreement.h"
#include "export/carve_export.h"
#include "export/point_cloud_compare.h"
#include "pipeline/carve_request.h"
#include "pipeline/project.h"

namespace raycarve {

using ProgressCallback = std::function<void(const CarveProgress&)>;

// What a run of the pipeline is for. `raycarve carve` runs every stage and writes the outputs;
// `holdout` leaves every k-th photo out of the carve and stops after the surface; `benchmark`
// carves the same views once per visibility method (CarvePipeline::CarveWith).
struct PipelineScope {
  std::string command = "carve";  // names the command in messages: "raycarve <command>: ..."
  int min_images = 2;             // registered images (and loaded photos) the command needs
  // > 0: every k-th photo in name order is left out of everything the carve sees (its sparse
  // observations too) and kept apart in held_out_views().
  int hold_out_every = 0;
  // The distant pixels when already found for these views (a tile job takes its plan's: the rays
  // and the counts, no masks): used instead of searching the photos again. Null: searched (where
  // the rules ask for it).
  const DistantPixels* distant = nullptr;
  ProgressCallback progress;           // during the carve stage (optional)
  std::function<void()> progress_end;  // after the carve stage (optional: ends a progress bar)
};

// A carve joined from tiles (`raycarve tile merge`): the plan it came from, and the final
// threshold its tiles judged with.
// The tiles' joined cores (JoinTileCores) and the coarse levels' volume they were carved from.
struct JoinedTiles {
  Volume joined;
  Volume coarse;
};

struct TiledCarveInfo {
  std::string plan_id;
  int jobs = 0;  // 0: not a tiled carve
  Eigen::Vector3i tiles_per_axis = Eigen::Vector3i::Ones();
  int overlap = 0;
  double final_threshold = 0.0;
  double final_pattern_threshold = 0.0;
};

// What the stages produced, for the report and the summary. Filled stage by stage.
struct CarveRun {
  // Load views (and masks).
  std::string model_path;
  std::string image_path;
  std::string output_path;
  Bounds bounds;
  CaptureLayout layout;
  exporter::SupportingPlane plane;  // the plane the subject stands on
  // The ground under it held solid by the carve (CarveRequest::hold_ground); empty: none.
  Ground ground;
  // The plane's footprint (the sparse points on it), masked or not: the mesh is levelled onto it
  // (CarveRequest::level_support); empty: no plane, or no point on it.
  Ground support;
  std::string ground_reason;  // why there is none, or where it is
  // The distant pixels (CarveRequest::distant_free_space): what was judged and found; `rays` is
  // left empty here (the carve takes them).
  DistantPixels distant;
  std::string distant_reason;  // why none were looked for (empty when they were)
  // The ground pixels (CarveRequest::ground_free_space), likewise; their rays are carved with
  // the distant pixels' (a tile job gets both in its plan's rays, and no counts of these).
  DistantPixels ground_pixels;
  std::string ground_pixels_reason;
  int num_views = 0;  // the views carved
  int num_missing_images = 0;
  int masks_from_files = 0;
  int masks_from_backdrop = 0;
  // Automatic backdrop masks found in a minority of the photos: not used (see AgreeMasks).
  int backdrop_masks_dropped = 0;
  // The spread floor used (CarveOptions::spread_floor) and why.
  double spread_floor = 0.0;
  std::string spread_floor_reason;
  // The views that judge the sparse points for the threshold
  // (CarveOptions::threshold_seen_views) and why.
  bool threshold_seen_views = false;
  std::string threshold_views_reason;
  std::vector<PhotoMaskInfo> mask_photos;  // per view: where its mask came from, what was found
  std::vector<std::string> view_names;     // the views carved, in carve order
  ColourCalibration colour;
  // How large a voxel of the carve's grid is in the photos: its side over the median pixel
  // footprint at the volume's centre (0 when no photo sees the centre), and the resolution
  // whose voxel would span one pixel (what the photos can support).
  double voxel_pixels = 0.0;
  int supported_resolution = 0;
  // The default --resolution when it was lowered to supported_resolution (0: not lowered).
  int resolution_lowered_from = 0;
  // The default --resolution when the box narrowed to the masks' hull (Bounds::around_hull) was
  // carved coarser, so that a voxel spans kNarrowedVoxelPixels (0: not).
  int hull_resolution_from = 0;
  int hull_resolution = 0;  // ... and the resolution carved
  // Masks agree.
  MaskAgreementStatistics mask_agreement;
  // Carve.
  std::unique_ptr<CarveResult> result;
  TiledCarveInfo tiled;  // jobs > 0: joined from tiles
  // Surface and colour.
  size_t num_mesh_triangles = 0;
  size_t num_mesh_vertices = 0;
  exporter::MeshTopology mesh_topology;
  exporter::MeshColouringSummary mesh_colouring;  // the smooth mesh's (vertices 0 otherwise)
  exporter::MeshRefinementSummary mesh_refinement;
  exporter::SelfIntersectionRepair mesh_self_intersections;
  exporter::MeshTextureSummary mesh_texture;
  exporter::MeshPartsSummary mesh_parts;
  exporter::SilhouetteFitSummary mesh_silhouettes;
  exporter::SupportLevelling mesh_levelling;
  double mesh_final_smoothing_mean_move = 0.0;  // world units
  int64_t mesh_small_components_removed = 0;
  int64_t mesh_grid_wall_vertices = 0;  // on the grid's wall: left out of the cloud
  int64_t mesh_wall_triangles_removed = 0;  // left out of the mesh (on the wall, no sparse point)
  // Of those, the ones beyond the frames of all but one photo (ModelMesh::uncovered_...).
  int64_t mesh_uncovered_triangles_removed = 0;
  // And the ones fewer than two photos see (a scene's: ModelMesh::unseen_...).
  int64_t mesh_unseen_triangles_removed = 0;
  // Vertices fewer than two photos see, kept within a voxel of what they see
  // (ModelMesh::unseen_vertices_kept).
  int64_t mesh_unseen_vertices_kept = 0;
  int64_t mesh_triangles_before_walls = 0;
  // The share of the mesh's triangles that lay on the box's walls and were left out (0 when none),
  // those beyond the photos' frames aside.
  double WallShare() const {
    return mesh_triangles_before_walls > 0
               ? static_cast<double>(mesh_wall_triangles_removed -
                                     mesh_uncovered_triangles_removed -
                                     mesh_unseen_triangles_removed) /
                     mesh_triangles_before_walls
               : 0.0;
  }
  // Cloud.
  size_t num_cloud_points = 0;
  // The model's sparse points inside the grid against the cloud (accuracy: their 90% distance).
  bool has_sparse = false;
  exporter::CloudComparison sparse;
  // Write. The output folder as a COLMAP dense workspace: fused.ply and fused.ply.vis (links to
  // cloud.ply and cloud.ply.vis) and the sparse model in sparse/. Empty when sparse/ was written;
  // otherwise why it was not (an input there, or a folder raycarve did not write).
  std::string dense_sparse_skipped;
  // Each stage's wall time, in order: load_project, agree_masks, carve_setup, carve, colour,
  // mesh, export.
  std::vector<std::pair<std::string, double>> stage_seconds;
};

// The carve pipeline: load views -> masks agree -> check the volume -> carve -> surface ->
// cloud -> write. One controller for every command that carves, so that what holdout and
// benchmark measure is what carve writes. Each stage reads the request (its options), records
// its result in run() and its wall time in run().stage_seconds, and logs a line on what it did.
// Stages throw InputError on bad input; each needs the ones it reads from to have run (CHECKed).
class CarvePipeline {
 public:
  CarvePipeline(CarveRequest request, PipelineScope scope);
  ~CarvePipeline();

  // Every stage in order, writing the outputs (`raycarve carve`).
  const CarveRun& Run();

  // The stages. LockOutputs (carve's first) resolves the output folder and takes it for this run
  // (StagedOutputs' lock), so that a second run into it is refused before any work.
  void LockOutputs();
  void LoadViews();    // model, bounds, photos undistorted and masked, colour calibration
  // Automatic backdrop masks found in a minority of the photos go (DecideMasks); then the carved
  // views' backdrop masks agree across them (raycarve::AgreeMasks).
  void AgreeMasks();
  void CheckVolume();  // the grid fits in memory (CheckCarveFits) and the photos see the volume
  void PlanOutputs();  // what the outputs must not overwrite; the staging folder, made at once
  void Carve();        // incremental voxel colouring over the carved views
  void MakeSurface();  // the mesh: smooth (refined, coloured from the photos) or left to Write
  void SampleCloud();  // cloud.ply's points on the mesh and the views that see them
  void MeasureCloud();  // how far the model's sparse points lie from the cloud
  void WriteOutputs();  // every file into the staging folder, then moved into place

  // Every stage as Run does, with the carve from the tiles' joined cores (CarveFromTiles): `join`
  // makes them and reads the coarse volume, for the grid of the project as loaded (it throws
  // InputError where they do not fit it).
  const CarveRun& RunFromTiles(const std::function<JoinedTiles(const VoxelGrid&)>& join,
                               const TiledCarveInfo& tiled);

  // A carve split into tiles (carve/tiling.h; `raycarve tile`), after CheckVolume: the coarse
  // levels, one tile, and the carve stage from the tiles' joined cores (in place of Carve).
  CoarseCarve CarveCoarse() const;
  TileCarve CarveTileOf(const CoarseCarve& coarse, const TileRegion& tile) const;
  void CarveFromTiles(JoinedTiles tiles, const TiledCarveInfo& tiled);

  // A carve of the carved views with other options (their surface points filled in), without
  // touching run(): benchmark's methods. Throws InputError when the carve does not fit.
  CarveResult CarveWith(CarveOptions options,
                        const ProgressCallback& progress,
                        double progress_interval_seconds) const;

  const CarveRequest& request() const { return request_; }
  const LoadedProject& project() const { return project_; }
  // The views the carve sees: every loaded view, or the training views when holding out. (The
  // project's own `views` are moved here by LoadViews.)
  const std::vector<CalibratedView>& carved_views() const { return carved_; }
  // With hold_out_every: the held-out views, in name order.
  const std::vector<CalibratedView>& held_out_views() const { return held_out_; }
  // The reliable sparse points of the carved views (SurfacePointsOf).
  const std::vector<SurfacePoint>& surface_points() const { return surface_points_; }
  // The distant pixels' rays the carve takes (after CheckVolume; empty where none were looked for).
  const std::vector<DistantRay>& distant_rays() const { return distant_rays_; }
  // The distant pixels' counts (run().distant) with the rays: what a tile plan passes to its jobs.
  DistantPixels DistantFound() const;
  const exporter::ModelMesh& model() const { return model_; }
  const CarveRun& run() const { return run_; }

 private:
  // `options` with what the carve takes from the project: its sparse points, ground and
  // distant rays.
  CarveOptions FilledOptions(CarveOptions options) const;
  void RecordCarve();  // the log lines and stage times of run_.result's carve
  void DecideMasks();
  void DecideGround();  // run_.ground, once the masks are decided
  // Why the automatic rules for an object without masks (the spread floor, the threshold's seen
  // views) do not apply; "" where they do.
  std::string ObjectRulesWithheld() const;
  // Whether the capture is taken as an object (cameras around it) rather than a scene seen from
  // one side: --capture, or the cameras' layout.
  bool CaptureIsObject() const;
  // run_.spread_floor and run_.threshold_seen_views, once the masks are decided
  void DecideObjectRules();
  void FindDistant();   // distant_rays_ and run_.distant, once the masks are decided
  void FindGroundPixels();  // appends to distant_rays_, run_.ground_pixels, once the ground is
  using Clock = std::chrono::steady_clock;
  static double SecondsSince(Clock::time_point start);
  void RecordSeconds(const std::string& stage, double seconds);
  void WriteMasks(const std::filesystem::path& staging) const;
  // report.html (pipeline/report_page.h): the summary, preview.png, the convergence plot and
  // mesh.glb in a 3D view, read back from the staging folder.
  void WriteReportPage(const std::filesystem::path& staging) const;
  void WriteDenseWorkspace(const std::filesystem::path& staging);

  CarveRequest request_;  // CheckVolume may lower a default resolution
  const PipelineScope scope_;
  LoadedProject project_;
  std::vector<CalibratedView> carved_;
  std::vector<CalibratedView> held_out_;
  std::vector<SurfacePoint> surface_points_;
  std::vector<DistantRay> distant_rays_;
  exporter::ModelMesh model_;
  std::vector<exporter::ColouredPoint> points_;
  std::vector<std::vector<uint32_t>> visibility_;  // per point, image indices (COLMAP's .vis)
  std::vector<std::filesystem::path> mask_targets_;  // per carved view, under the output folder
  std::optional<WorkspacePaths> paths_;  // resolved by LockOutputs, reused by LoadViews
  std::unique_ptr<StagedOutputs> staged_;
  std::future<void> mesh_written_;  // the smooth mesh's file, written beside the cloud
  double export_seconds_ = 0.0;     // the cloud's sampling and the files
  bool loaded_ = false;
  CarveRun run_;
};

}  // namespace raycarve
