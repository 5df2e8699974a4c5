#pragma once
// Internal to carve/: helpers shared by the files of the incremental carver (carver.h's
// implementation). Not installed for use outside carve/.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "calib/calibrated_view.h"
#include "carve/carver.h"
#include "carve/ray_cast_visibility.h"
#include "carve/voxel_colour_sums.h"

namespace raycarve {

using Clock = std::chrono::steady_clock;

inline double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

inline int64_t ElapsedNanoseconds(Clock::time_point since) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - since).count();
}

// Appends to `stats` the colour statistics of pixels [begin, end), grouped view by view (a new
// entry wherever the view changes).
void GatherColours(const std::vector<CalibratedView>& views,
                   const PixelRef* begin,
                   const PixelRef* end,
                   std::vector<ViewColourStats>* stats);

// Which part of CarveVolume's work a call does: all of it, or the parts a carve split into tiles
// runs in separate processes (carve/tiling.h).
struct CarveStages {
  int first_level = 0;  // the levels before it are skipped: `start` is where it begins
  int last_level = -1;  // the levels after it are skipped (-1: up to the final level)
  std::unique_ptr<Volume> start;  // first_level's start volume; needed when first_level > 0
  // first_level's voxels held by CarveOptions::lod_carve_depth (DeepInteriorVoxels of the level
  // before it), when first_level > 0.
  std::vector<int64_t> start_held;
  // The final level's views when they differ from the carve's (a tile's; not owned).
  const std::vector<CalibratedView>* final_views = nullptr;
  // The final level's thresholds, when known (FinalLevelThresholds): not estimated again there.
  bool final_thresholds_given = false;
  double final_threshold = 0.0;
  double final_pattern_threshold = 0.0;
  bool final_visual_hull = true;  // off: the final level carves no visual hull
  // Where set, receives the volume the levels' thresholds were measured through (the first
  // level's first pass: CarveOptions::threshold_seen_views; null without one), for
  // FinalLevelThresholds.
  std::unique_ptr<Volume>* seen_through_out = nullptr;
  // After the last level: the final level's removal of components, silhouette repair and
  // colouring (off: the result's surface is left empty).
  bool finish = true;
};

CarveResult CarveLevels(const std::vector<CalibratedView>& views,
                        const Eigen::AlignedBox3d& box,
                        const CarveOptions& options,
                        CarveStages stages,
                        const std::function<void(const CarveProgress&)>& progress,
                        double progress_interval_seconds);

// The thresholds the final level of a carve of `views` with `options` judges with (estimated from
// the sparse points where options ask for it, through `seen_through` where the carve's first
// pass gave one (CarveStages::seen_through_out); otherwise options' own).
void FinalLevelThresholds(const std::vector<CalibratedView>& views,
                          const Eigen::AlignedBox3d& box,
                          const CarveOptions& options,
                          const Volume* seen_through,
                          double* threshold,
                          double* pattern_threshold);

}  // namespace raycarve
