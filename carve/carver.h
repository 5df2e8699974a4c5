#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <queue>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "calib/calibrated_view.h"
#include "carve/consistency.h"
#include "carve/silhouette_repair.h"
#include "carve/level_of_detail.h"
#include "carve/ray_cast_visibility.h"
#include "carve/surface_evidence.h"
#include "carve/view_workers.h"
#include "carve/voxel_colour_sums.h"
#include "carve/free_space.h"
#include "carve/ground.h"
#include "carve/visual_hull.h"
#include "carve/volume.h"

namespace raycarve {

// How visibility is kept: the seed paper's ray casting or one of its two baselines. They share
// everything else (grid, surface, footprints, consistency, colouring).
enum class CarveMethod {
  kRay,     // ray casting: an image of rays per view, stepped only where a voxel was carved
  kGvc,     // GVC: item buffers re-rendered every pass, every surface voxel judged per pass
  kGvcLdi,  // GVC-LDI: per-pixel depth-sorted lists of surface voxels, updated incrementally
};
std::string CarveMethodToString(CarveMethod method);
bool CarveMethodFromString(const std::string& text, CarveMethod* method);

// The order in which the CVSVL hands out voxels (the seed paper's section 4).
enum class CarveOrder {
  kFifo,           // first in, first out
  kVisiblePixels,  // most visible pixels first: most evidence first
};
std::string CarveOrderToString(CarveOrder order);
bool CarveOrderFromString(const std::string& text, CarveOrder* order);

// How a voxel is judged (the seed paper's section 4).
enum class CarveDecision {
  kThreshold,     // carve when the consistency error exceeds the threshold
  kReprojection,  // also carve consistent voxels when that lowers the pixels' reprojection error
};
std::string CarveDecisionToString(CarveDecision decision);
bool CarveDecisionFromString(const std::string& text, CarveDecision* decision);

// Incremental voxel colouring with ray-cast visibility (Batchelor, Mukundan, Green).
// Known surface (CarveOptions::protect_surface_points): around a surface point's projection in a
// view that saw it, within this many of its projected voxel widths, the surface is taken to lie no
// farther than the farthest such point; a voxel closer than that by less than the margin (in
// voxels) is at or behind the known surface in that view and is not carved by colour.
constexpr double kKnownSurfaceRadiusVoxels = 2.0;
// ... or this many times the view's spacing of the known surface (the median distance from an
// observation to its nearest neighbour in that photo), when that is wider: finer grids need the
// same cover of the photo.
constexpr double kKnownSurfaceRadiusSpacings = 1.0;
constexpr double kKnownSurfaceMarginVoxels = 1.0;
// The largest consistent error (RGB units) where none is given or can be chosen from the data.
constexpr double kDefaultThreshold = 30.0;

struct CarveOptions {
  // The smallest shorter side of a photo reduced for a coarse level of detail.
  static constexpr int kMinReducedSide = 48;

  CarveMethod method = CarveMethod::kRay;
  // Voxels along the longest axis of the box; voxels are cubes.
  int resolution = 128;
  // How visible pixels are judged (see consistency.h).
  ConsistencyMethod consistency = ConsistencyMethod::kMeanColour;
  // Largest consistent error, in RGB units (0-255). Negative: nothing is consistent, so every
  // voxel seen by min_views views is carved.
  double threshold = kDefaultThreshold;
  // consistency kPatchCorrelation: a voxel that passes the colour test but whose views see
  // texture is carved when 1 - NCC of their patterns exceeds this (0..2).
  double pattern_threshold = 0.5;
  // Adaptive allowance: the threshold grows by this times the voxel's within-view colour spread
  // (see ConsistencyTest); 0 holds every voxel to `threshold`.
  double adaptive_threshold = 0.0;
  // Spread floor: the threshold is at least this times the voxel's within-view colour spread. A
  // voxel across a texture edge takes a different share of each side in each photo, so its
  // photos disagree by up to its spread at the true surface; a threshold taken from narrow
  // tracks of sparse points (neighbouring photos, which agree on everything) is below that.
  // 0: no floor.
  double spread_floor = 0.0;
  // With auto_threshold and no masks: each sparse point's voxel (and the voxel in front of it) is
  // judged, to measure the threshold, from every photo that sees it through a first carve of the
  // coarsest level at the tracks' threshold, not only from the photos of its track
  // (ThresholdRule::seen_through). A SIFT track is a few neighbouring photos that agree on the
  // surface and on the space just in front of it alike; the carve judges a voxel from every photo
  // that sees it. The first carve (too much carved at the tracks' low threshold) lets a photo
  // see a point more often than the final volume would: the threshold errs high, and keeps.
  bool threshold_seen_views = false;
  // Views a voxel must be seen by to be judged; voxels seen by fewer stay.
  int min_views = 2;
  // A voxel is judged only when at least min_views views each see this share of its projected
  // outline (its visible pixels against the area of the cube's projection); otherwise it stays.
  // A voxel seen through a small hole shows the views the hole's rim, not itself: judging it lets
  // one wrong carve drill a tunnel. 0: any pixel counts.
  double min_coverage = 0.0;
  // After the final level, give back to every masked view's object pixels the model that colour
  // carving took from their rays (RepairSilhouettes): holes the masks contradict are closed.
  bool repair_silhouettes = false;
  // Refuse a grid whose carving structures would need more memory than this (GiB).
  double max_memory_gib = 8.0;
  // With ray casting, how Vis(V) is found (see ray_cast_visibility.h); the carving is the same
  // either way.
  VisLookup vis_lookup = VisLookup::kFootprint;
  // When views carry masks: carve the silhouettes' visual hull before colouring (background
  // pixels are always left out of Vis(V) and consistency).
  bool visual_hull = true;
  CarveOrder order = CarveOrder::kFifo;
  // kReprojection (ray casting only; after Slabaugh et al., carving only): besides what the
  // threshold carves, a consistent V is carved when the pixels of Vis(V) would be explained
  // better by the voxels their rays reach next (each such voxel's colour recomputed with them)
  // than by V: the summed |pixel - colour| of the pixels involved drops. A pixel whose ray would
  // leave the volume costs `threshold`. Voxels seen by fewer than min_views views are kept.
  // (Alone, the reprojection test stalls in empty space, where V and the voxels behind it
  // explain the pixels equally badly: measured, it carved 4% of the demo volume.)
  CarveDecision decision = CarveDecision::kThreshold;
  // Levels of detail (Prock and Dyer): 1 carves at `resolution` directly; L > 1 carves at
  // resolution / 2^(L-1) first, then augments by lod_band voxels, subdivides and carves again, up
  // to `resolution` (which must be divisible by 2^(L-1)). 0 (kAutomaticLevels): as many levels
  // as keep the coarsest at 64 voxels or more (level_of_detail.h; the command line's default).
  int lod_levels = 1;
  int lod_band = 1;
  // A finer level refines the coarser level's surface and does not dig through it: its voxels
  // whose parent lay more than this many coarse voxels inside the coarse solid (26-neighbour
  // steps to a carved voxel or to the grid's edge) are never carved by the consistency test.
  // As the band lets a finer level put back what the coarser one carved, this lets it carve what
  // the coarser one kept, by as much; deeper, a wrong carve at the finer level's lower threshold
  // would open a hole through a surface that the coarser level judged whole (measured on the
  // generated unmasked scenes: a striped box holed at 128 voxels, whole at 64). 0: no limit.
  int lod_carve_depth = 1;
  // Set by CarveVolume per level: the voxels lod_carve_depth holds (indices, sorted).
  std::vector<int64_t> interior_held;
  // With levels of detail: a level whose voxels are f = 2^k times the final ones carves the
  // photos reduced f times (block means; ReduceView), so that a voxel covers about as many
  // pixels at every level (fewer while any photo's shorter side would drop below
  // kMinReducedSide pixels). Off: every level carves the full photos.
  bool lod_reduce_images = true;
  // Rays per pixel side at the final level (supersampling): the photos are enlarged this many
  // times (EnlargeView: bilinear) before their rays are cast, so that a voxel smaller than a
  // pixel is still crossed by rays from every view that sees it and judged on the photo's mean
  // over its projection, not left unjudged where rays pass between voxels. Coarse levels follow
  // (with lod_reduce_images, a level of voxels f times the final ones carves the photos scaled
  // supersample / f). 1: the photos as they are. kAutomaticSupersample: the smallest power of
  // two that makes a final voxel span kMinRaysPerVoxel ray spacings (the median over the views
  // at the box's centre; at most kMaxSupersample).
  static constexpr int kAutomaticSupersample = 0;
  static constexpr int kMaxSupersample = 4;
  static constexpr double kMinRaysPerVoxel = 1.5;
  int supersample = 1;
  // After the final level converges: carve every 26-connected component of solid voxels with
  // fewer voxels than this (specks in empty space whose pixels agree by chance), then carry on
  // carving from what they hid; repeated while any is found (at most 4 rounds). 0: keep all.
  int min_component_voxels = 0;
  // After that: carve every 26-connected component that holds none of surface_points (within a
  // voxel) where the density of the points on the model's surface predicts at least this many,
  // and whose surface is below a quarter of the largest component's: hull leftovers floating
  // beside the object, which no photo saw texture on. 0: keep all.
  double unsupported_component_points = 0.0;
  // With levels of detail: a level whose voxels are 2^k times the final ones judges with
  // threshold x lod_threshold_scale^k. A coarse voxel straddles more texture edges and spans more
  // depth, so its views' mean colours disagree more even on the true surface; at the final
  // threshold the coarse levels carve into the object, and what they carve no finer level puts
  // back beyond the band. The coarse levels need only remove what is clearly empty; the final
  // level judges with `threshold`. 1: every level uses `threshold`. Measured in the README
  // (the demo at 128 voxels, threshold 30: completeness 44% with 1, 94.4% with 1.1, 93.7% with
  // 1.2, 92.7% with 1.5, 92.0% in one level).
  double lod_threshold_scale = 1.2;
  // Threads for ray casting with the footprint lookup and fifo order (see batch_voxels). The
  // carving is identical for any count. < 1: one per core. Other methods, ray lists and the
  // evidence order use one.
  int num_threads = 1;
  // Ray casting with the footprint lookup, fifo order and the threshold decision, without
  // incremental statistics: the CVSVL is handed out this many voxels at a time. The voxels of a
  // batch are judged at once against the rays as they stand (Vis(V) found and tested for each, on
  // every thread), the inconsistent ones are carved in queue order, then the rays that ended in
  // them step on (on every thread) and the voxels they reach are queued, batch by batch in queue
  // order. A voxel of the batch that a ray of another carved voxel reaches is queued again and
  // judged with its new pixels, as any voxel whose visibility changed is. The batch is the unit
  // of work handed to the threads, so it does not depend on their number and neither does the
  // carving. 1: the seed paper's one voxel at a time (its threads then share each voxel's views:
  // a hand-over per voxel, which costs more than it saves on fine grids). Measured in
  // docs/studies/carving.md.
  int batch_voxels = 64;
  // Ray casting: keep colour statistics per voxel and view incrementally (voxel_colour_sums.h):
  // evaluating a voxel reads its sums, and Vis(V) is found only for voxels carved (or judged by
  // the reprojection decision). Same carving, 56 bytes per view and voxel holding rays.
  bool incremental_statistics = false;
  // Points known to lie on the surface (reliable sparse points, with the views that saw them:
  // indices into the carve's views). Used by auto_threshold and protect_surface_points.
  std::vector<SurfacePoint> surface_points;
  // Choose each level's threshold (and pattern_threshold) from the data (EstimateThreshold over
  // surface_points at that level's grid and photos): with masks, the auto_threshold_quantile of
  // the errors of the voxels known to be on the surface; without, the equal-error threshold
  // between them and the voxels just in front of them. `threshold` (and lod_threshold_scale) and
  // pattern_threshold are the fallback where fewer than 20 points can be judged.
  bool auto_threshold = false;
  double auto_threshold_quantile = 0.99;
  // kPatchCorrelation: choose pattern_threshold from the data as auto_threshold does, also when
  // `threshold` is given.
  bool auto_pattern_threshold = false;
  // Voxels holding a surface point are never carved by the consistency test (the visual hull and
  // the removal of small components still carve them): known surface stops carving that runs
  // away through one wrong carve.
  bool protect_surface_points = false;
  // Free space from the sparse points (> 0): a surface point seen by a view was seen across
  // empty space, so the voxels on the sight line from the view's centre to the point are carved
  // before colouring, up to this many voxels short of the point. 0: off.
  double free_space_margin_voxels = 0.0;
  // Free space from distant pixels (calib/distant_pixels.h; `view` indexes the carve's views) and
  // ground pixels (carve/ground_pixels.h): each ray's voxels are carved before colouring, up to
  // its length and to the known surface where one lies on it
  // (CarveDistantRays), at the final level of detail only: a ray a pixel wide would take a coarse
  // voxel whole, the object's part of it too (measured over the unmasked table: patchwork forward
  // F 89.6% carving at every level, 90.2% at the final one; the other rows within 0.1). Empty: none.
  std::vector<DistantRay> distant_rays;
  // The mean-colour error corrected for the number of views (MeanColourDifference). CarveVolume
  // sets it where no view has a mask and the threshold is auto (a number given is on the seed
  // paper's scale): there colour alone carves the empty space, and voxels seen
  // by two or three views passed too easily (on the generated unmasked scenes, half the cloud's
  // points seen by three photos lay off the truth, 3% of those seen by twelve). With masks it
  // cost 0.2-0.3 dB held out on the dino sets (the hull already bounds the object, and the
  // silhouette voxels, seen by few views, went), so it stays off there.
  bool correct_view_count = false;
  // The ground under an unmasked capture (see carve/ground.h): its voxels are never carved by
  // the consistency test. Empty: none.
  Ground ground;

  bool IsValid(std::string* reason) const;
};

struct CarveProgress {
  int level = 0;   // with levels of detail: the level carving now, 0 the coarsest
  int levels = 1;
  int64_t evaluated = 0;
  int64_t carved = 0;
  int64_t queued = 0;
  double seconds = 0.0;  // since carving started (after set-up)
  // Told once as each level after the first starts its set-up (the start volume from the level
  // before, the photos scaled, the rays cast to the first solid voxels: tens of seconds at 1024
  // voxels); the counts are the levels' before it.
  bool setting_up = false;
};

// One point of the carving curve (the paper's Figure 6).
struct CurveSample {
  double seconds = 0.0;
  // Voxels carved so far, besides the visual hull's. With levels of detail, in voxels of the
  // final resolution (a coarse voxel counts for the fine voxels it holds), so that the curve
  // steps back where a refinement's band puts voxels back.
  int64_t carved = 0;
  int64_t evaluated = 0;
};

struct CarveStatistics {
  std::string visibility;  // "ray (footprint)", "ray (ray_lists)", "gvc" or "gvc_ldi"
  int passes = 1;          // GVC: item-buffer renders (passes over the surface); others 1
  int threads = 1;         // threads of the final level's carving
  int views_with_masks = 0;
  SilhouetteRepairSummary silhouette_repair;  // CarveOptions::repair_silhouettes
  int64_t visual_hull_carved = 0;    // voxels removed by the silhouette pre-carve
  // Voxels removed by the sparse points' sight lines (CarveOptions::free_space_margin_voxels),
  // summed over the levels (each level's own voxels), and at the first level; the sight lines
  // that crossed the grid; the time (part of set-up).
  int64_t free_space_carved = 0;
  int64_t free_space_level0_carved = 0;
  int64_t free_space_sight_lines = 0;
  // Of the final level's, those not drawn: down through the held ground (CarveFreeSpace).
  int64_t free_space_through_ground = 0;
  double free_space_seconds = 0.0;
  // Voxels removed by the distant pixels' rays (CarveOptions::distant_rays, final level); the rays
  // that crossed the grid.
  int64_t distant_carved = 0;
  int64_t distant_rays = 0;
  int64_t distant_through_ground = 0;  // rays not drawn: down through the held ground
  // Likewise for the ground pixels' rays (those with a finite length).
  int64_t ground_seen_carved = 0;
  int64_t ground_seen_rays = 0;
  std::string FreeSpaceSummary() const;  // one line for the log
  std::string FloaterSummary() const;    // likewise, for the components without sparse points
  int64_t ground_voxels = 0;  // under the ground (CarveOptions::ground), at the final level
  int64_t beyond_ground_carved = 0;  // below the plane past the ground's edge, every level
  int64_t component_carved = 0;  // small components removed (CarveOptions::min_component_voxels)
  // Components removed for holding no sparse point (CarveOptions::unsupported_component_points):
  // how many, their voxels, and the points they were expected to hold (the largest).
  int64_t unsupported_components = 0;
  int64_t unsupported_component_carved = 0;
  double unsupported_largest_expected = 0.0;
  double visual_hull_seconds = 0.0;  // its time (part of set-up)
  Eigen::Vector3i dimensions = Eigen::Vector3i::Zero();
  double voxel_size = 0.0;
  int64_t num_voxels = 0;
  int64_t initial_surface = 0;
  int64_t final_surface = 0;
  int64_t final_solid = 0;
  int64_t carved = 0;     // voxels removed: the grid's voxels less the final solid ones
  int64_t evaluated = 0;  // evaluations, over every level
  int64_t visible_surface = 0;  // final surface voxels seen by at least one pixel
  double setup_seconds = 0.0;   // volume and rays
  // The carving loops: the convergence time. With levels of detail, everything after the first
  // level's set-up (refinements and later set-ups too).
  double carve_seconds = 0.0;
  double colour_seconds = 0.0;  // colouring the final surface
  // Where the threads' time went in carving and colouring (every level; ViewWorkers::Times): the
  // wall time of the parallel sections, and per thread its work in them (its waiting is the rest).
  // Set-up, and the serial parts between sections, are outside.
  double parallel_seconds = 0.0;
  std::vector<double> thread_work_seconds;
  int64_t parallel_runs = 0;
  int64_t inline_runs = 0;  // sections run on one thread because the others fell behind
  size_t peak_memory_bytes = 0;  // volume, visibility structures and the CVSVL
  std::vector<CurveSample> curve;
  std::vector<LevelStatistics> levels;  // one per level of detail (one without)
  // The mean over usable pixels of |pixel - colour of the voxel it sees| (RGB), a pixel seeing
  // no voxel counting `threshold`: after carving, and (with the reprojection decision, as it
  // costs a pass over the surface) before; -1 when not computed.
  double reprojection_error_before = -1.0;
  double reprojection_error_after = -1.0;

  std::string Summary() const;
  // "2 threads", with the share of the parallel runs the calling thread ran alone where the
  // workers were left (ViewWorkers: the other cores were busy).
  std::string ThreadsText() const;
};

struct ColouredVoxel {
  int64_t index = 0;
  Eigen::Vector3f colour = Eigen::Vector3f::Zero();  // RGB 0-255, mean of the visible pixels
  int num_views = 0;
  int num_pixels = 0;  // 0: no view sees this surface voxel (it is not coloured)
};

struct CarveResult {
  explicit CarveResult(const VoxelGrid& grid) : volume(grid) {}
  Volume volume;
  std::vector<ColouredVoxel> surface;  // every final surface voxel, in index order
  CarveStatistics statistics;
};

// Estimates the memory of carving `views` over `box` with `options` and returns false, with a
// reason giving the sizes, when the options are invalid or the estimate exceeds
// options.max_memory_gib.
bool CheckCarveFits(const std::vector<CalibratedView>& views,
                    const Eigen::AlignedBox3d& box,
                    const CarveOptions& options,
                    std::string* reason);

// How much of a box the views see, from a lattice of 17^3 points over it: per view the share of
// the points in front of its camera and on a valid pixel of its photo, and the share of the
// points that at least `min_views` views see.
struct BoxCoverage {
  std::vector<double> view_share;  // per view, in view order
  double seen_share = 0.0;         // by min_views views or more
};
BoxCoverage MeasureBoxCoverage(const std::vector<CalibratedView>& views,
                               const Eigen::AlignedBox3d& box,
                               int min_views);

// The photos' enlargement at the final level (CarveOptions::supersample, resolved where automatic):
// 1 when the views' pixels at the box's centre are at most 1 / kMinRaysPerVoxel of a voxel.
int FinalSupersample(const std::vector<CalibratedView>& views,
                     const Eigen::AlignedBox3d& box,
                     const CarveOptions& options);

// Carves the volume over `box` seen by `views` until no voxel whose visibility changed is
// inconsistent. `progress` (optional) is called about every `progress_interval_seconds` of
// carving. Options must pass CheckCarveFits (CHECKed).
CarveResult CarveVolume(const std::vector<CalibratedView>& views,
                        const Eigen::AlignedBox3d& box,
                        const CarveOptions& options,
                        const std::function<void(const CarveProgress&)>& progress = {},
                        double progress_interval_seconds = 1.0);

}  // namespace raycarve
