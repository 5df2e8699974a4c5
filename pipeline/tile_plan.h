#pragma once
// The files of a carve split into tiles (carve/tiling.h) and the jobs that run them, for
// `raycarve tile plan | run | merge`. A plan folder holds:
//
//   plan.json        what every job needs: the carve's arguments, the grid, the tiles, the final
//                    threshold, and per tile its region, whether it has work, and the memory and
//                    time a job should ask for
//   coarse.bin       the coarse levels' volume (one bit a voxel), which every tile starts from
//   distant.bin      the distant pixels' rays the plan found, which every job takes as they are
//   tile_<i>.bin     job i's result: its tile's core (written by `tile run`, under a temporary
//                    name and renamed)
//   tiles.sbatch, merge.sbatch, submit_slurm.sh   a Slurm array job, the merge after it
//   tiles.k8s.yaml, merge.k8s.yaml                a Kubernetes indexed Job and the merge Job
//   run_local.sh     the same jobs as processes on this machine (pipeline/tile_jobs.h)
//
// Every file a job reads names the plan it belongs to (plan_id: a hash of the arguments, the grid
// and the coarse volume), so that a part from another plan, or a plan made again since, is
// refused by name instead of being merged.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/calibrated_view.h"
#include "calib/distant_pixels.h"
#include "carve/carver.h"
#include "carve/tiling.h"
#include "carve/volume.h"

namespace raycarve {

struct TilePlan {
  static constexpr int kSchema = 1;
  std::string plan_id;            // 16 hex digits
  std::string working_directory;  // where the arguments' relative paths start
  std::vector<std::string> arguments;  // the carve's options as given to `tile plan`
  int resolution = 0;                  // the final grid (after any lowering of the default)
  Eigen::Vector3i dimensions = Eigen::Vector3i::Zero();
  Eigen::Vector3i coarse_dimensions = Eigen::Vector3i::Zero();
  Eigen::Vector3i tiles_per_axis = Eigen::Vector3i::Ones();
  int overlap = 0;
  double final_threshold = 0.0;
  double final_pattern_threshold = 0.0;
  struct Tile {
    TileRegion region;
    int job = -1;  // its job's index (0 .. jobs - 1), or -1 when the coarse volume is empty there
    int64_t coarse_solid = 0;  // coarse voxels of its region that are solid
    // Photos whose view the region's box reaches (BoxInView): those its job needs.
    int views = 0;
    double memory_gib = 0.0;   // what its job should ask for
    double minutes = 0.0;
  };
  std::vector<Tile> tiles;
  int jobs = 0;
  double merge_memory_gib = 0.0;
  double merge_minutes = 0.0;

  const Tile* TileOfJob(int job) const;
};

// The plan of carving `views` over `box` with `options` in `tiles` (per axis) with `overlap`,
// from the coarse levels' result: the tiles, which have work (a solid coarse voxel, with the band
// the final level starts from, in their region), the photos in view of each, the memory and time
// each job should ask for (from `load_seconds`, the photos' loading, and the coarse levels' own
// time), and the plan id. `arguments` are the carve's options as given, in `working_directory`.
TilePlan MakeTilePlan(const std::vector<CalibratedView>& views,
                      const Eigen::AlignedBox3d& box,
                      const CarveOptions& options,
                      const CoarseCarve& coarse,
                      const Eigen::Vector3i& tiles,
                      int overlap,
                      double load_seconds,
                      std::vector<std::string> arguments,
                      std::string working_directory);

// Short hex digest (FNV-1a, 64 bits) of bytes, for plan ids.
std::string HexDigest(const std::string& bytes);

// plan.json's text, and the plan read back from it. ReadTilePlan throws InputError naming the
// file and the field that is missing or wrong.
std::string TilePlanJson(const TilePlan& plan);
TilePlan ReadTilePlan(const std::string& path);

// The coarse volume and the parts, one bit a voxel behind a header that names the plan and the
// block of voxels. Written atomically; read back with every size checked against the plan
// (InputError naming the file and what does not match).
void WriteCoarseVolume(const std::string& path, const std::string& plan_id, const Volume& volume);
std::vector<uint64_t> ReadCoarseVolume(const std::string& path, const TilePlan& plan);
void WriteTilePart(const std::string& path, const TilePlan& plan, int job,
                   const std::vector<uint64_t>& core_bits);
std::vector<uint64_t> ReadTilePart(const std::string& path, const TilePlan& plan, int job);

// The distant pixels the plan found (CarvePipeline::DistantFound: the rays and the counts), for
// the jobs, so that each does not search every photo again. Read back with the plan's id and the
// sizes checked (InputError naming the file).
void WriteDistantPixels(const std::string& path, const std::string& plan_id,
                        const DistantPixels& distant);
DistantPixels ReadDistantPixels(const std::string& path, const TilePlan& plan);

// The part file of a job, and the plan's other files, in `folder`.
std::string TilePartPath(const std::string& folder, int job);


}  // namespace raycarve
