// raycarve tile plan | run | merge: a carve split into tiles that separate processes (or a
// cluster's jobs) carve, then joined (carve/tiling.h, pipeline/tile_plan.h).
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <glog/logging.h>

#include "calib/input_error.h"
#include "carve/level_of_detail.h"
#include "carve/tiling.h"
#include "pipeline/carve_pipeline.h"
#include "pipeline/carve_summary.h"
#include "pipeline/output_files.h"
#include "pipeline/tile_jobs.h"
#include "pipeline/tile_plan.h"
#include "plugin/carve_flags.h"
#include "plugin/commands.h"
#include "plugin/option_parser.h"
#include "plugin/progress_display.h"

namespace raycarve {
namespace {

namespace fs = std::filesystem;

constexpr const char* kTileFlags[] = {"tiles", "tile_overlap", "tile_path"};

// "2" or "2,2,1": tiles per axis.
Eigen::Vector3i ParseTiles(const std::string& text) {
  Eigen::Vector3i tiles;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%d,%d,%d%c", &tiles.x(), &tiles.y(), &tiles.z(), &extra) == 3) {
    return tiles;
  }
  int n = 0;
  if (std::sscanf(text.c_str(), "%d%c", &n, &extra) == 1) return Eigen::Vector3i::Constant(n);
  throw InputError("raycarve tile plan: --tiles must be N or NX,NY,NZ, got '" + text + "'");
}

// The arguments of argv from `first` on, less the tile flags (and their values).
std::vector<std::string> CarveArguments(int argc, char** argv, int first) {
  std::vector<std::string> result;
  for (int i = first; i < argc; ++i) {
    const std::string argument = argv[i];
    bool tile_flag = false;
    for (const char* name : kTileFlags) {
      const std::string flag = std::string("--") + name;
      if (argument == flag) {
        tile_flag = true;
        ++i;  // its value
      } else if (argument.rfind(flag + "=", 0) == 0) {
        tile_flag = true;
      }
    }
    if (!tile_flag) result.push_back(argument);
  }
  return result;
}

// The carve request that a plan's arguments give (as `tile plan` parsed them).
CarveRequest RequestOfPlan(const TilePlan& plan, const std::string& command) {
  CarveRequest request;
  CarveFlagText text;
  OptionParser parser(command, "");
  AddCarveFlags(&parser, &request, &text);
  std::vector<std::string> arguments = {"raycarve", command};
  arguments.insert(arguments.end(), plan.arguments.begin(), plan.arguments.end());
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  if (!parser.Parse(static_cast<int>(argv.size()), argv.data(), 2)) {
    throw InputError("raycarve " + command + ": the plan's arguments ask for help, not a carve");
  }
  ApplyCarveFlags(parser, text, &request);
  return request;
}

// Runs in the plan's working directory, where its arguments' relative paths start.
void EnterWorkingDirectory(const TilePlan& plan, const std::string& plan_path) {
  if (plan.working_directory.empty() || fs::equivalent(plan.working_directory, fs::current_path())) {
    return;
  }
  if (chdir(plan.working_directory.c_str()) != 0) {
    throw InputError(plan_path + ": field working_directory: cannot enter " +
                     plan.working_directory);
  }
}

// The grid the pipeline will carve must be the plan's: the same project, options and photos.
void CheckSameGrid(const CarvePipeline& pipeline, const TilePlan& plan, const std::string& path) {
  const VoxelGrid grid(pipeline.project().bounds.box, pipeline.request().options.resolution);
  if (pipeline.request().options.resolution != plan.resolution ||
      grid.dimensions() != plan.dimensions) {
    throw InputError(path + ": the plan's grid (resolution " + std::to_string(plan.resolution) +
                     ") is not what the project gives now (resolution " +
                     std::to_string(pipeline.request().options.resolution) +
                     "): the project changed since the plan; run raycarve tile plan again");
  }
}

CoarseCarve ReadCoarse(const CarvePipeline& pipeline, const TilePlan& plan,
                       const std::string& folder) {
  std::vector<int> resolutions;
  std::string reason;
  const CarveOptions& options = pipeline.request().options;
  if (!LevelResolutions(options.resolution, options.lod_levels, &resolutions, &reason) ||
      resolutions.size() < 2) {
    throw InputError("raycarve tile: the plan's options give one level of detail");
  }
  const VoxelGrid grid(pipeline.project().bounds.box, resolutions[resolutions.size() - 2]);
  const std::string path = (fs::path(folder) / "coarse.bin").string();
  if (grid.dimensions() != plan.coarse_dimensions) {
    throw InputError(path + ": the coarse grid does not match the project's");
  }
  CoarseCarve coarse(grid);
  coarse.volume = Volume(grid, ReadCoarseVolume(path, plan));
  coarse.final_threshold = plan.final_threshold;
  coarse.final_pattern_threshold = plan.final_pattern_threshold;
  return coarse;
}

double StageSeconds(const CarveRun& run, const std::string& stage) {
  for (const auto& [name, seconds] : run.stage_seconds) {
    if (name == stage) return seconds;
  }
  return 0.0;
}

// The pipeline's scope for a step, with its progress on `display`.
PipelineScope ScopeOf(const std::string& command, ProgressDisplay* display) {
  PipelineScope scope;
  scope.command = command;
  scope.progress = [display](const CarveProgress& p) { display->Update(p); };
  scope.progress_end = [display] { display->Finish(); };
  return scope;
}

std::string PlanFolder(const std::string& plan_path) {
  return fs::absolute(plan_path).parent_path().string();
}

// The plan's folder (and its logs/), made: never inside the photos' or the model's folder.
fs::path MakePlanFolder(const std::string& tile_path, const std::vector<std::string>& inputs) {
  const fs::path folder = fs::absolute(tile_path);
  for (const std::string& input : inputs) {
    const fs::path inside = fs::weakly_canonical(input);
    const fs::path plan_folder = fs::weakly_canonical(folder);
    if (std::mismatch(inside.begin(), inside.end(), plan_folder.begin(), plan_folder.end()).first ==
        inside.end()) {
      throw InputError("raycarve tile plan: --tile_path " + tile_path + " lies in the input " +
                       input + ": give another --tile_path");
    }
  }
  std::error_code error;
  fs::create_directories(folder / "logs", error);
  if (error) throw InputError(tile_path + ": cannot make the plan's folder: " + error.message());
  return folder;
}

// What the plan holds and how to run it.
void PrintPlan(const TilePlan& plan, const CoarseCarve& coarse, const Eigen::Vector3i& tiles,
               int overlap, const std::string& folder, const std::string& plan_path) {
  std::printf("tile plan %s: a %dx%dx%d grid (resolution %d) in %dx%dx%d tiles, overlap %d; "
              "%d with work (%d empty in the coarse volume)\n",
              plan.plan_id.c_str(), plan.dimensions.x(), plan.dimensions.y(), plan.dimensions.z(),
              plan.resolution, tiles.x(), tiles.y(), tiles.z(), overlap, plan.jobs,
              static_cast<int>(plan.tiles.size()) - plan.jobs);
  std::printf("coarse levels: %.1f s; final threshold %.2f\n",
              coarse.statistics.carve_seconds + coarse.statistics.setup_seconds,
              plan.final_threshold);
  std::printf("plan: %s\n", plan_path.c_str());
  std::printf("run:  %s/submit_slurm.sh (Slurm), kubectl apply -f %s/tiles.k8s.yaml (Kubernetes),\n"
              "      or %s/run_local.sh (this machine); one job: raycarve tile run --plan %s --index I\n",
              folder.c_str(), folder.c_str(), folder.c_str(), plan_path.c_str());
}

int RunTilePlan(int argc, char** argv) {
  CarveRequest request;
  CarveFlagText text;
  std::string tiles_text = "2";
  int overlap = 8;
  std::string tile_path;
  OptionParser parser(
      "tile plan",
      "Plans a carve split into tiles: carves the coarse levels of detail over the whole volume "
      "once, cuts the final grid into tiles, and writes plan.json, coarse.bin and the jobs that "
      "carve the tiles: a Slurm array (tiles.sbatch, merge.sbatch, submit_slurm.sh), a Kubernetes "
      "indexed Job (tiles.k8s.yaml, merge.k8s.yaml) and run_local.sh. Takes carve's options; "
      "`raycarve tile run` carves one tile, `raycarve tile merge` joins them and writes what "
      "carve writes.");
  AddCarveFlags(&parser, &request, &text);
  parser.BeginGroup("Tiles");
  parser.AddDefault("tiles", &tiles_text, "tiles along each axis: N, or NX,NY,NZ");
  parser.AddDefault("tile_overlap", &overlap,
                    "final voxels each tile carves beyond its own on every side (even, at least 2)");
  parser.AddDefault("tile_path", &tile_path,
                    "the plan's folder (default: the output folder's path with _tiles appended)");
  parser.SetBasicOptions({"workspace_path", "resolution", "tiles", "tile_overlap", "tile_path"});
  parser.AddExample("raycarve tile plan --workspace_path P --resolution 512 --tiles 2",
                    "8 tiles; then P/raycarve_tiles/submit_slurm.sh or run_local.sh");
  if (!parser.Parse(argc, argv, 3)) return 0;
  ApplyCarveFlags(parser, text, &request);
  const Eigen::Vector3i tiles = ParseTiles(tiles_text);

  ProgressDisplay display;
  const PipelineScope scope = ScopeOf("tile plan", &display);
  CarvePipeline pipeline(request, scope);
  pipeline.LoadViews();
  pipeline.AgreeMasks();
  pipeline.CheckVolume();
  const CarveOptions& options = pipeline.request().options;
  const Eigen::AlignedBox3d& box = pipeline.project().bounds.box;
  std::string reason;
  if (!CheckTiling(box, options, tiles, overlap, &reason)) {
    throw InputError("raycarve tile plan: " + reason);
  }
  if (tile_path.empty()) tile_path = pipeline.run().output_path + "_tiles";
  const fs::path folder = MakePlanFolder(tile_path, {pipeline.run().image_path, pipeline.run().model_path});

  const CoarseCarve coarse = pipeline.CarveCoarse();
  const TilePlan plan = MakeTilePlan(pipeline.carved_views(), box, options, coarse, tiles, overlap,
                                     StageSeconds(pipeline.run(), "load_project"),
                                     CarveArguments(argc, argv, 3), fs::current_path().string());
  if (plan.jobs == 0) {
    throw InputError("the coarse levels left no solid voxel: no tile has work (raycarve carve "
                     "would keep nothing either; see its summary for what to try)");
  }
  const std::string plan_path = (folder / "plan.json").string();
  WriteCoarseVolume((folder / "coarse.bin").string(), plan.plan_id, coarse.volume);
  WriteDistantPixels((folder / "distant.bin").string(), plan.plan_id, pipeline.DistantFound());
  char self[4096];
  const ssize_t length = readlink("/proc/self/exe", self, sizeof(self) - 1);
  const std::string raycarve = length > 0 ? std::string(self, length) : std::string(argv[0]);
  WriteTileJobScripts(folder.string(), plan, raycarve, plan_path);
  WriteTextFileAtomically(plan_path, TilePlanJson(plan));

  PrintPlan(plan, coarse, tiles, overlap, folder.string(), plan_path);
  return 0;
}

int RunTileRun(int argc, char** argv) {
  std::string plan_path;
  int job = -1;
  OptionParser parser("tile run",
                      "Carves one tile of a plan (raycarve tile plan) and writes its part, "
                      "tile_<index>.bin, beside the plan. Jobs are independent: run them in any "
                      "order, anywhere the plan's paths are, and again after a failure.");
  parser.AddRequired("plan", &plan_path, "the plan.json that raycarve tile plan wrote");
  parser.AddDefault("index", &job,
                    "the job's index, 0 .. jobs - 1 (Slurm: $SLURM_ARRAY_TASK_ID; Kubernetes: "
                    "$JOB_COMPLETION_INDEX); required");
  if (!parser.Parse(argc, argv, 3)) return 0;
  const TilePlan plan = ReadTilePlan(plan_path);
  const std::string folder = PlanFolder(plan_path);
  const TilePlan::Tile* tile = plan.TileOfJob(job);
  if (tile == nullptr) {
    throw InputError("raycarve tile run: --index " + std::to_string(job) + ": the plan has jobs 0 to " +
                     std::to_string(plan.jobs - 1));
  }
  const DistantPixels distant = ReadDistantPixels((fs::path(folder) / "distant.bin").string(), plan);
  EnterWorkingDirectory(plan, plan_path);
  ProgressDisplay display;
  PipelineScope scope = ScopeOf("tile run", &display);
  scope.distant = &distant;
  CarvePipeline pipeline(RequestOfPlan(plan, "tile run"), scope);
  pipeline.LoadViews();
  pipeline.AgreeMasks();
  pipeline.CheckVolume();
  CheckSameGrid(pipeline, plan, plan_path);
  const CoarseCarve coarse = ReadCoarse(pipeline, plan, folder);
  LOG(INFO) << "carving tile " << tile->region.index << " (job " << job << " of " << plan.jobs
            << "): voxels " << tile->region.lo.transpose() << " .. " << tile->region.hi.transpose();
  const TileCarve carved = pipeline.CarveTileOf(coarse, tile->region);
  const std::vector<uint64_t> core = CoreBits(carved.volume, tile->region);
  int64_t solid = 0;
  for (uint64_t word : core) solid += __builtin_popcountll(word);
  WriteTilePart(TilePartPath(folder, job), plan, job, core);
  std::printf("tile %d (job %d): %lld solid voxels of %lld in its core; %lld evaluations, "
              "%lld pixels hidden by the outside; %.1f s carving; part %s\n",
              tile->region.index, job, static_cast<long long>(solid),
              static_cast<long long>(tile->region.CoreVoxels()),
              static_cast<long long>(carved.statistics.evaluated),
              static_cast<long long>(carved.occluded_pixels),
              carved.statistics.carve_seconds + carved.statistics.setup_seconds,
              TilePartPath(folder, job).c_str());
  return 0;
}

int RunTileMerge(int argc, char** argv) {
  std::string plan_path;
  OptionParser parser("tile merge",
                      "Joins the tiles of a plan (raycarve tile plan, tile run), carves on where "
                      "the whole volume's visibility shows more, and writes what raycarve carve "
                      "writes, to the output folder of the plan's options. Refuses a missing "
                      "part, or one from another plan, by name.");
  parser.AddRequired("plan", &plan_path, "the plan.json that raycarve tile plan wrote");
  if (!parser.Parse(argc, argv, 3)) return 0;
  const TilePlan plan = ReadTilePlan(plan_path);
  const std::string folder = PlanFolder(plan_path);
  // Every part is read before the photos: a missing or foreign one stops the merge at once.
  std::vector<TileRegion> regions;
  std::vector<std::vector<uint64_t>> cores;
  std::vector<int> missing;
  for (const TilePlan::Tile& tile : plan.tiles) {
    regions.push_back(tile.region);
    cores.emplace_back();
    if (tile.job < 0) continue;
    const std::string part = TilePartPath(folder, tile.job);
    if (!fs::exists(part)) {
      missing.push_back(tile.job);
      continue;
    }
    cores.back() = ReadTilePart(part, plan, tile.job);
  }
  if (!missing.empty()) {
    std::string list;
    for (int job : missing) list += (list.empty() ? "" : ", ") + std::to_string(job);
    throw InputError(TilePartPath(folder, missing.front()) + ": missing; " +
                     std::to_string(missing.size()) + " of " + std::to_string(plan.jobs) +
                     " parts are missing (jobs " + list + "): run raycarve tile run --plan " +
                     plan_path + " --index I for each");
  }
  const DistantPixels distant = ReadDistantPixels((fs::path(folder) / "distant.bin").string(), plan);
  EnterWorkingDirectory(plan, plan_path);
  ProgressDisplay display;
  PipelineScope scope = ScopeOf("tile merge", &display);
  scope.distant = &distant;
  const CarveRequest request = RequestOfPlan(plan, "tile merge");
  TiledCarveInfo tiled;
  tiled.plan_id = plan.plan_id;
  tiled.jobs = plan.jobs;
  tiled.tiles_per_axis = plan.tiles_per_axis;
  tiled.overlap = plan.overlap;
  tiled.final_threshold = plan.final_threshold;
  tiled.final_pattern_threshold = plan.final_pattern_threshold;
  CarvePipeline pipeline(request, scope);
  const CarveRun& run = pipeline.RunFromTiles(
      [&](const VoxelGrid& grid) {
        if (grid.dimensions() != plan.dimensions) {
          throw InputError(plan_path + ": the plan's grid is not what the project gives now: "
                           "the project changed since the plan; run raycarve tile plan again");
        }
        return JoinedTiles{JoinTileCores(grid, regions, cores),
                           ReadCoarse(pipeline, plan, folder).volume};
      },
      tiled);
  std::fputs(CarveSummaryText(request, run).c_str(), stdout);
  return 0;
}

}  // namespace

int RunTile(int argc, char** argv) {
  const std::string usage =
      "Usage: raycarve tile <step> [options]   (raycarve tile <step> --help)\n\n"
      "A carve split into tiles that separate processes or a cluster's jobs carve:\n"
      "  plan    carve the coarse levels once, cut the grid into tiles, write the jobs\n"
      "  run     carve one tile of a plan (--plan plan.json --index I)\n"
      "  merge   join the tiles and write what raycarve carve writes (--plan plan.json)\n";
  const std::string step = argc >= 3 ? argv[2] : "";
  if (step == "plan") return RunTilePlan(argc, argv);
  if (step == "run") return RunTileRun(argc, argv);
  if (step == "merge") return RunTileMerge(argc, argv);
  if (step.empty() || step == "--help" || step == "-h") {
    std::cout << usage;
    return 0;
  }
  throw InputError("unknown step '" + step + "' (plan, run or merge)");
}

}  // namespace raycarve
