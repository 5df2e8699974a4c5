#include "carve/carver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include <glog/logging.h>
#include <opencv2/imgproc.hpp>

#include "carve/free_space.h"
#include "carve/item_buffer_visibility.h"
#include "carve/layered_depth_visibility.h"
#include "carve/patch_correlation.h"
#include "carve/ray_image.h"


#include "carve/carver_internal.h"
#include "carve/incremental_carver.h"

namespace raycarve {
namespace {

// How a level's photos are scaled: reduced `reduce` times (the level's voxel scale over the final
// enlargement, halved while any photo's shorter side would fall below
// CarveOptions::kMinReducedSide) or enlarged `enlarge` times (the final enlargement over the
// level's voxel scale). One of the two is 1.
struct ImageScale {
  int reduce = 1;
  int enlarge = 1;
};
ImageScale LevelImageScale(const std::vector<CalibratedView>& views, int level_resolution,
                           const CarveOptions& options, int supersample) {
  const int voxel_scale = options.resolution / level_resolution;
  ImageScale scale;
  if (voxel_scale == 1) {
    scale.enlarge = supersample;
    return scale;
  }
  if (!options.lod_reduce_images) return scale;
  if (supersample >= voxel_scale) {
    scale.enlarge = supersample / voxel_scale;
    return scale;
  }
  int factor = voxel_scale / supersample;
  int shortest = std::numeric_limits<int>::max();
  for (const CalibratedView& view : views) shortest = std::min({shortest, view.width, view.height});
  while (factor > 1 && shortest / factor < CarveOptions::kMinReducedSide) factor /= 2;
  scale.reduce = factor;
  return scale;
}

// `views` scaled as `scale` says, into `scaled`; returns `views` itself when both are 1.
const std::vector<CalibratedView>& ScaleViews(const std::vector<CalibratedView>& views,
                                              ImageScale scale,
                                              std::vector<CalibratedView>* scaled) {
  scaled->clear();
  if (scale.reduce == 1 && scale.enlarge == 1) return views;
  scaled->resize(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    (*scaled)[v] = scale.reduce > 1 ? ReduceView(views[v], scale.reduce)
                                    : EnlargeView(views[v], scale.enlarge);
  }
  return *scaled;
}

// With --threshold auto (or an automatic pattern threshold): the level's thresholds from the
// sparse points (EstimateThreshold), recorded in *level_statistics. A level that carves enlarged
// photos (`enlarge` > 1) takes the thresholds of the photos as they are (`photos`) at a grid
// `enlarge` times coarser, the finest they resolve: interpolated rays add samples, not evidence,
// and the errors of voxels finer than a pixel understate how far views must disagree for space
// to be empty (measured on the paper scene at 512 voxels: estimated on the enlarged photos the
// threshold fell from 17.6 to 9.7, and within 2 voxels of 256 the objects' precision fell from
// 95.2% to 85.8% and their completeness from 98.3% to 94.1%).
void ChooseLevelThresholds(const std::vector<CalibratedView>& level_views,
                           const std::vector<CalibratedView>& photos,
                           const Eigen::AlignedBox3d& box,
                           int level_resolution,
                           int enlarge,
                           const CarveOptions& options,
                           CarveOptions* level_options,
                           LevelStatistics* level_statistics,
                           const Volume* seen_through = nullptr) {
  const bool auto_pattern = options.consistency == ConsistencyMethod::kPatchCorrelation &&
                            (options.auto_threshold || options.auto_pattern_threshold);
  if (!options.auto_threshold && !auto_pattern) return;
  ThresholdRule rule;
  rule.test_method = options.consistency;
  rule.min_views = options.min_views;
  rule.masked = std::any_of(level_views.begin(), level_views.end(),
                            [](const CalibratedView& view) { return !view.mask.empty(); });
  rule.correct_view_count = level_options->correct_view_count;
  rule.quantile = options.auto_threshold_quantile;
  rule.fallback = level_options->threshold;
  rule.pattern_fallback = options.pattern_threshold;
  rule.seen_through = seen_through;
  const int resolution = std::max(1, level_resolution / enlarge);
  if (enlarge > 1) level_statistics->threshold_resolution = resolution;
  level_statistics->estimate = EstimateThreshold(enlarge > 1 ? photos : level_views,
                                                 VoxelGrid(box, resolution),
                                                 options.surface_points, rule);
  level_statistics->threshold_from_data =
      level_statistics->estimate.points_judged >= kMinThresholdPoints;
  if (options.auto_threshold) level_options->threshold = level_statistics->estimate.threshold;
  if (auto_pattern) level_options->pattern_threshold = level_statistics->estimate.pattern_threshold;
}

// Whether the thresholds are measured through a first pass (CarveOptions::threshold_seen_views).
bool MeasuresThroughFirstPass(const std::vector<CalibratedView>& views, const CarveOptions& options) {
  return options.threshold_seen_views && options.auto_threshold &&
         std::none_of(views.begin(), views.end(),
                      [](const CalibratedView& view) { return !view.mask.empty(); });
}

// The first level carved at the thresholds its sparse points' tracks give (`level_options`),
// the volume the levels' thresholds are then measured through; its threshold and time into
// *level_statistics.
std::unique_ptr<Volume> FirstPass(const std::vector<CalibratedView>& level_views,
                                  const Eigen::AlignedBox3d& box,
                                  const CarveOptions& level_options,
                                  LevelStatistics* level_statistics) {
  const Clock::time_point start = Clock::now();
  IncrementalCarver pass(level_views, box, level_options);
  while (pass.Step()) {
  }
  level_statistics->first_pass_threshold = level_options.threshold;
  level_statistics->first_pass_seconds = SecondsSince(start);
  return std::make_unique<Volume>(pass.volume());
}

// The final level: specks left in empty space go, then pieces without the sparse points their
// size predicts; carving carries on behind each.
void RemoveComponents(const CarveOptions& options, IncrementalCarver* carver, CarveStatistics* statistics) {
  for (int round = 0; options.min_component_voxels > 1 && round < 4; ++round) {
    const int64_t removed = carver->RemoveSmallComponents(options.min_component_voxels);
    if (removed == 0) break;
    statistics->component_carved += removed;
    while (carver->Step()) {
    }
  }
  if (options.unsupported_component_points > 0.0 && !options.surface_points.empty()) {
    int64_t components = 0;
    double expected = 0.0;
    const int64_t removed = carver->RemoveUnsupportedComponents(
        options.surface_points, options.unsupported_component_points, &components, &expected);
    if (removed > 0) {
      statistics->unsupported_components = components;
      statistics->unsupported_component_carved = removed;
      statistics->unsupported_largest_expected = expected;
      while (carver->Step()) {
      }
    }
  }
}

// The level's worker threads' times, added to the carve's.
void AddWorkerTimes(const IncrementalCarver& carver, CarveStatistics* statistics) {
  const ViewWorkers::Times times = carver.worker_times();
  statistics->parallel_seconds += times.wall_seconds;
  statistics->parallel_runs += times.runs;
  statistics->inline_runs += times.inline_runs;
  if (statistics->thread_work_seconds.size() < times.busy_seconds.size()) {
    statistics->thread_work_seconds.resize(times.busy_seconds.size(), 0.0);
  }
  for (size_t t = 0; t < times.busy_seconds.size(); ++t) {
    statistics->thread_work_seconds[t] += times.busy_seconds[t];
  }
}

// The photos a level carves: `photos` scaled as the level says (into `scaled`). A tile's views
// (carve/tiling.h: TileViews) are the carve's photos with the pixels it leaves out marked
// invalid, though they hold photo colours: enlarged, the photos are, and an enlarged pixel is
// left out where its nearest photo pixel is (not where it blends one).
const std::vector<CalibratedView>& LevelViews(const std::vector<CalibratedView>& views,
                                              const std::vector<CalibratedView>& photos,
                                              ImageScale image_scale,
                                              std::vector<CalibratedView>* scaled) {
  const bool enlarged_tile = &photos != &views && image_scale.enlarge > 1;
  const std::vector<CalibratedView>& level_views =
      ScaleViews(enlarged_tile ? views : photos, image_scale, scaled);
  for (size_t v = 0; enlarged_tile && v < views.size(); ++v) {
    cv::Mat kept;
    cv::resize(photos[v].valid, kept, (*scaled)[v].valid.size(), 0, 0, cv::INTER_NEAREST);
    (*scaled)[v].valid &= kept;
  }
  return level_views;
}

// A level's options: the carve's at the level's resolution, one level, its threshold scaled.
CarveOptions LevelOptions(const CarveOptions& options, int level_resolution, int level,
                          int num_levels, bool correct_view_count) {
  CarveOptions level_options = options;
  level_options.correct_view_count = correct_view_count;
  level_options.resolution = level_resolution;
  level_options.lod_levels = 1;
  level_options.interior_held.clear();  // set per level from the coarser one (CarveLevels)
  if (level + 1 < num_levels) level_options.distant_rays.clear();  // see CarveOptions
  level_options.threshold =
      options.threshold * std::pow(options.lod_threshold_scale, num_levels - 1 - level);
  return level_options;
}

// A level's set-up into its statistics.
void RecordLevelStart(const IncrementalCarver& carver, const CarveOptions& level_options,
                      ImageScale image_scale, double setup_seconds,
                      LevelStatistics* level_statistics) {
  level_statistics->resolution = level_options.resolution;
  level_statistics->image_factor = image_scale.reduce;
  level_statistics->image_enlargement = image_scale.enlarge;
  level_statistics->threshold = level_options.threshold;
  level_statistics->pattern_threshold = level_options.pattern_threshold;
  level_statistics->dimensions = carver.volume().grid().dimensions();
  level_statistics->start_solid = carver.volume().num_solid();
  level_statistics->interior_held = static_cast<int64_t>(level_options.interior_held.size());
  level_statistics->setup_seconds = setup_seconds;
}

// What the first level's set-up did (visibility, visual hull, free space) into `statistics`;
// returns the voxels the visual hull carved, in final voxels (`scale` a level voxel).
int64_t RecordFirstLevel(IncrementalCarver& carver, const CarveOptions& options,
                         const VoxelGrid& final_grid, int64_t scale, double setup_seconds,
                         CarveStatistics* statistics) {
  statistics->visibility = carver.visibility().Name();
  if (options.method == CarveMethod::kRay) {
    statistics->visibility += " (" + VisLookupToString(options.vis_lookup) + ")";
  }
  statistics->initial_surface = carver.volume().num_surface();
  statistics->views_with_masks = carver.visual_hull().views_with_masks;
  statistics->visual_hull_carved = carver.visual_hull().carved;
  statistics->visual_hull_seconds = carver.visual_hull().seconds;
  statistics->free_space_level0_carved = carver.free_space().carved;
  statistics->setup_seconds = setup_seconds;
  if (options.decision == CarveDecision::kReprojection) {
    statistics->reprojection_error_before = carver.MeanReprojectionError();
  }
  return std::min(final_grid.num_voxels(), carver.visual_hull().carved * scale);
}

// A finished level's counts into its statistics and the carve's.
void RecordLevelEnd(const IncrementalCarver& carver, LevelStatistics* level_statistics,
                    CarveStatistics* statistics) {
  level_statistics->carved =
      carver.carved() + carver.visual_hull().carved + carver.free_space().carved +
      carver.distant().carved + carver.ground_seen().carved + carver.beyond_ground_carved();
  level_statistics->free_space_carved = carver.free_space().carved;
  statistics->free_space_carved += carver.free_space().carved;
  statistics->free_space_sight_lines = carver.free_space().sight_lines;
  statistics->free_space_through_ground = carver.free_space().through_ground;
  statistics->free_space_seconds += carver.free_space().seconds;
  statistics->distant_carved += carver.distant().carved;
  statistics->distant_rays = carver.distant().sight_lines;
  statistics->distant_through_ground = carver.distant().through_ground;
  statistics->ground_seen_carved += carver.ground_seen().carved;
  statistics->ground_seen_rays = carver.ground_seen().sight_lines;
  level_statistics->evaluated = carver.evaluated();
  level_statistics->protected_kept = carver.protected_kept();
  statistics->ground_voxels = carver.ground_voxels();
  statistics->beyond_ground_carved += carver.beyond_ground_carved();
  level_statistics->final_solid = carver.volume().num_solid();
  statistics->evaluated += carver.evaluated();
  statistics->passes = std::max(statistics->passes, carver.passes());
  statistics->threads = carver.threads();
  statistics->peak_memory_bytes = std::max(statistics->peak_memory_bytes, carver.MemoryBytes());
}

// The carving curve's samples and the progress reports across the levels.
struct LevelsClock {
  Clock::time_point start;  // when the first level's carving began
  double next_report = 0.0;
  double next_sample = 0.0;
  int64_t hull_carved = 0;  // the first level's visual hull, in final voxels
};

// One sample of the carving curve: voxels removed, in final voxels (`scale` a level voxel), less
// what the visual hull carved.
void SampleCurve(const IncrementalCarver& carver, int64_t scale, const VoxelGrid& final_grid,
                 const LevelsClock& clock, CarveStatistics* statistics) {
  const int64_t removed = std::max<int64_t>(
      0, final_grid.num_voxels() - std::min(final_grid.num_voxels(),
                                            carver.volume().num_solid() * scale));
  statistics->curve.push_back({SecondsSince(clock.start),
                               std::max<int64_t>(0, removed - clock.hull_carved),
                               statistics->evaluated + carver.evaluated()});
}

// Runs the level's carver to the end, sampling the curve and reporting progress.
void RunLevel(int level, int num_levels, int64_t scale, const VoxelGrid& final_grid,
              const std::function<void(const CarveProgress&)>& progress,
              double progress_interval_seconds, IncrementalCarver* carver, LevelsClock* clock,
              CarveStatistics* statistics) {
  SampleCurve(*carver, scale, final_grid, *clock, statistics);
  for (int64_t next_check = 1024; carver->Step();) {
    if (carver->evaluated() < next_check) continue;
    next_check = carver->evaluated() + 1024;
    const double seconds = SecondsSince(clock->start);
    if (seconds >= clock->next_sample) {
      SampleCurve(*carver, scale, final_grid, *clock, statistics);
      clock->next_sample = seconds + 0.05;
    }
    if (progress && seconds >= clock->next_report) {
      progress({level, num_levels, statistics->evaluated + carver->evaluated(), carver->carved(),
                static_cast<int64_t>(carver->queue_size()), seconds});
      clock->next_report = seconds + progress_interval_seconds;
    }
  }
}

// With masks: each photo's object pixels get back the model carving took from their rays; the
// restored voxels are final, so a new carver over the repaired volume only colours it.
void RepairSilhouettesAndRecolour(const std::vector<CalibratedView>& views,
                                  const CarveOptions& options,
                                  std::unique_ptr<IncrementalCarver>* carver,
                                  CarveStatistics* statistics) {
  if (!options.repair_silhouettes || statistics->views_with_masks == 0) return;
  Volume repaired = (*carver)->volume();
  statistics->silhouette_repair = RepairSilhouettes(views, &repaired, options.num_threads);
  if (statistics->silhouette_repair.restored_voxels == 0) return;
  CarveOptions colouring = options;
  colouring.lod_levels = 1;
  colouring.visual_hull = false;
  colouring.free_space_margin_voxels = 0.0;
  colouring.distant_rays.clear();
  colouring.protect_surface_points = false;
  colouring.min_component_voxels = 0;
  colouring.unsupported_component_points = 0.0;
  statistics->peak_memory_bytes = std::max(statistics->peak_memory_bytes, (*carver)->MemoryBytes());
  AddWorkerTimes(**carver, statistics);
  carver->reset();
  *carver = std::make_unique<IncrementalCarver>(views, std::move(repaired), colouring);
}

// The carve's end: its statistics, and with `stages.finish` the surface coloured.
CarveResult FinishLevels(const CarveStages& stages, int last_level, int num_levels,
                         const std::function<void(const CarveProgress&)>& progress,
                         const LevelsClock& clock, IncrementalCarver* carver,
                         CarveStatistics statistics) {
  statistics.carve_seconds = SecondsSince(clock.start);
  statistics.dimensions = carver->volume().grid().dimensions();
  statistics.voxel_size = carver->volume().grid().voxel_size();
  statistics.num_voxels = carver->volume().grid().num_voxels();
  statistics.carved = statistics.num_voxels - carver->volume().num_solid();

  const Clock::time_point colour_start = Clock::now();
  CarveResult result{carver->volume().grid()};
  if (stages.finish) {
    result.surface = carver->ColourSurface();
    statistics.reprojection_error_after = carver->surface_reprojection_error();
    for (const ColouredVoxel& voxel : result.surface) {
      if (voxel.num_pixels > 0) ++statistics.visible_surface;
    }
    statistics.colour_seconds = SecondsSince(colour_start);
    AddWorkerTimes(*carver, &statistics);
  }
  statistics.final_surface = carver->volume().num_surface();
  statistics.final_solid = carver->volume().num_solid();
  result.volume = std::move(*carver->mutable_volume());
  result.statistics = std::move(statistics);
  if (progress) {
    progress({last_level, num_levels, result.statistics.evaluated, result.statistics.carved,
              0, result.statistics.carve_seconds});
  }
  return result;
}

}  // namespace

// The levels of detail in one function: they share the carver (a level starts from the one
// before), the curve's clock and the progress schedule; what stands alone is in the helpers above.
// `stages` says which levels run (CarveVolume: all) and what the last one does after carving.
CarveResult CarveLevels(const std::vector<CalibratedView>& views,
                        const Eigen::AlignedBox3d& box,
                        const CarveOptions& options,
                        CarveStages stages,
                        const std::function<void(const CarveProgress&)>& progress,
                        double progress_interval_seconds) {
  std::string reason;
  CHECK(CheckCarveFits(views, box, options, &reason)) << reason;
  std::vector<int> resolutions;
  CHECK(LevelResolutions(options.resolution, options.lod_levels, &resolutions, &reason)) << reason;
  const int num_levels = static_cast<int>(resolutions.size());
  const int first_level = stages.first_level;
  const int last_level = stages.last_level < 0 ? num_levels - 1 : stages.last_level;
  CHECK(first_level >= 0 && first_level <= last_level && last_level < num_levels);
  CHECK(first_level == 0 || stages.start) << "a later level needs its start volume";
  const VoxelGrid final_grid(box, options.resolution);

  CarveStatistics statistics;
  LevelsClock clock;
  clock.next_report = progress_interval_seconds;
  std::unique_ptr<IncrementalCarver> carver;
  std::vector<CalibratedView> scaled_views;  // a level's photos, when reduced or enlarged
  const int supersample = FinalSupersample(views, box, options);
  // The first level's first pass (CarveOptions::threshold_seen_views).
  std::unique_ptr<Volume> seen_through;
  // Only where the threshold comes from the same corrected errors: a --threshold given as a
  // number is on the seed paper's scale.
  const bool correct_view_count =
      options.auto_threshold &&
      std::none_of(views.begin(), views.end(),
                   [](const CalibratedView& view) { return !view.mask.empty(); });
  for (int level = first_level; level <= last_level; ++level) {
    const Clock::time_point level_start = Clock::now();
    const bool final_level = level + 1 == num_levels;
    CarveOptions level_options =
        LevelOptions(options, resolutions[level], level, num_levels, correct_view_count);
    const ImageScale image_scale =
        LevelImageScale(views, resolutions[level], options, supersample);
    std::unique_ptr<Volume> start_volume;
    if (level == first_level && level > 0) {
      start_volume = std::move(stages.start);
      level_options.interior_held = std::move(stages.start_held);
    } else if (level > 0) {
      if (progress) {
        CarveProgress setting_up{level, num_levels, statistics.evaluated, carver->carved(), 0,
                                 SecondsSince(clock.start)};
        setting_up.setting_up = true;
        progress(setting_up);
      }
      const VoxelGrid level_grid(box, resolutions[level]);
      start_volume = std::make_unique<Volume>(
          RefineVolume(carver->volume(), level_grid, options.lod_band));
      level_options.interior_held =
          DeepInteriorVoxels(carver->volume(), level_grid, options.lod_carve_depth);
      carver.reset();  // the coarse level's rays and queue go before the fine level's come
    }
    scaled_views.clear();  // the last level's go before this one's are made
    const std::vector<CalibratedView>& photos =
        final_level && stages.final_views ? *stages.final_views : views;
    const std::vector<CalibratedView>& level_views =
        LevelViews(views, photos, image_scale, &scaled_views);
    LevelStatistics level_statistics;
    if (final_level && stages.final_thresholds_given) {
      level_options.threshold = stages.final_threshold;
      level_options.pattern_threshold = stages.final_pattern_threshold;
      level_statistics.threshold_given = true;
    } else {
      ChooseLevelThresholds(level_views, photos, box, resolutions[level], image_scale.enlarge,
                            options, &level_options, &level_statistics, seen_through.get());
      if (level == 0 && MeasuresThroughFirstPass(views, options)) {
        seen_through = FirstPass(level_views, box, level_options, &level_statistics);
        level_options.threshold = LevelOptions(options, resolutions[level], level, num_levels,
                                               correct_view_count).threshold;
        ChooseLevelThresholds(level_views, photos, box, resolutions[level], image_scale.enlarge,
                              options, &level_options, &level_statistics, seen_through.get());
      }
    }
    if (final_level && !stages.final_visual_hull) level_options.visual_hull = false;
    if (level == 0) {
      carver = std::make_unique<IncrementalCarver>(level_views, box, level_options);
    } else {
      carver = std::make_unique<IncrementalCarver>(level_views, std::move(*start_volume),
                                                   level_options);
    }
    // A voxel of this level holds `scale` final voxels (up to the grid's edge).
    const int64_t scale = int64_t{1} << (3 * (num_levels - 1 - level));
    RecordLevelStart(*carver, level_options, image_scale, SecondsSince(level_start),
                     &level_statistics);
    if (level == first_level) {
      // The curve leaves out what the visual hull carved; the sparse points' sight lines are in
      // its first value.
      clock.hull_carved = RecordFirstLevel(*carver, options, final_grid, scale,
                                           SecondsSince(level_start), &statistics);
      clock.start = Clock::now();
    }
    RunLevel(level, num_levels, scale, final_grid, progress, progress_interval_seconds,
             carver.get(), &clock, &statistics);
    if (final_level && stages.finish) RemoveComponents(options, carver.get(), &statistics);
    SampleCurve(*carver, scale, final_grid, clock, &statistics);
    level_statistics.seconds = SecondsSince(level_start);
    RecordLevelEnd(*carver, &level_statistics, &statistics);
    statistics.levels.push_back(level_statistics);
    if (level < last_level || !stages.finish) AddWorkerTimes(*carver, &statistics);
  }
  if (stages.seen_through_out != nullptr) *stages.seen_through_out = std::move(seen_through);
  if (stages.finish) RepairSilhouettesAndRecolour(views, options, &carver, &statistics);
  return FinishLevels(stages, last_level, num_levels, progress, clock, carver.get(),
                      std::move(statistics));
}

CarveResult CarveVolume(const std::vector<CalibratedView>& views,
                        const Eigen::AlignedBox3d& box,
                        const CarveOptions& options,
                        const std::function<void(const CarveProgress&)>& progress,
                        double progress_interval_seconds) {
  return CarveLevels(views, box, options, CarveStages(), progress, progress_interval_seconds);
}

void FinalLevelThresholds(const std::vector<CalibratedView>& views,
                          const Eigen::AlignedBox3d& box,
                          const CarveOptions& options,
                          const Volume* seen_through,
                          double* threshold,
                          double* pattern_threshold) {
  CarveOptions level_options = options;
  level_options.correct_view_count =
      options.auto_threshold &&
      std::none_of(views.begin(), views.end(),
                   [](const CalibratedView& view) { return !view.mask.empty(); });
  LevelStatistics ignored;
  ChooseLevelThresholds(views, views, box, options.resolution,
                        FinalSupersample(views, box, options), options, &level_options, &ignored,
                        seen_through);
  *threshold = level_options.threshold;
  *pattern_threshold = level_options.pattern_threshold;
}

int FinalSupersample(const std::vector<CalibratedView>& views,
                     const Eigen::AlignedBox3d& box,
                     const CarveOptions& options) {
  if (options.supersample != CarveOptions::kAutomaticSupersample) return options.supersample;
  const double pixel = MedianPixelFootprint(views, box.center());
  if (!(pixel > 0.0)) return 1;
  const double spacings = VoxelGrid(box, options.resolution).voxel_size() / pixel;
  int supersample = 1;
  while (supersample < CarveOptions::kMaxSupersample &&
         supersample * spacings < CarveOptions::kMinRaysPerVoxel) {
    supersample *= 2;
  }
  return supersample;
}

}  // namespace raycarve
