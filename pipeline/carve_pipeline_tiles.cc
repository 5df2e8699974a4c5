// The carve pipeline's stages for a carve split into tiles (`raycarve tile`; carve/tiling.h):
// the coarse levels, one tile, and the carve from the tiles' joined cores.
#include <utility>

#include <glog/logging.h>

#include "pipeline/carve_pipeline.h"

namespace raycarve {

const CarveRun& CarvePipeline::RunFromTiles(
    const std::function<JoinedTiles(const VoxelGrid&)>& join, const TiledCarveInfo& tiled) {
  LockOutputs();
  LoadViews();
  AgreeMasks();
  CheckVolume();
  PlanOutputs();
  CarveFromTiles(join(VoxelGrid(project_.bounds.box, request_.options.resolution)), tiled);
  MakeSurface();
  SampleCloud();
  MeasureCloud();
  WriteOutputs();
  return run_;
}

CoarseCarve CarvePipeline::CarveCoarse() const {
  CHECK(loaded_);
  LOG(INFO) << "carving the coarse levels of detail over the whole volume ...";
  CoarseCarve coarse = CarveCoarseLevels(carved_, project_.bounds.box,
                                         FilledOptions(request_.options), scope_.progress,
                                         request_.progress_seconds);
  if (scope_.progress_end) scope_.progress_end();
  return coarse;
}

TileCarve CarvePipeline::CarveTileOf(const CoarseCarve& coarse, const TileRegion& tile) const {
  CHECK(loaded_);
  TileCarve carved = CarveTile(carved_, project_.bounds.box, FilledOptions(request_.options),
                               coarse, tile, scope_.progress, request_.progress_seconds);
  if (scope_.progress_end) scope_.progress_end();
  return carved;
}

void CarvePipeline::CarveFromTiles(JoinedTiles tiles, const TiledCarveInfo& tiled) {
  CHECK(loaded_);
  run_.tiled = tiled;
  LOG(INFO) << "carving on from the tiles' joined volume with the whole volume's visibility ...";
  run_.result = std::make_unique<CarveResult>(FinishTiledCarve(
      carved_, project_.bounds.box, FilledOptions(request_.options), std::move(tiles.joined),
      tiles.coarse, tiled.final_threshold, tiled.final_pattern_threshold, scope_.progress,
      request_.progress_seconds));
  RecordCarve();
}

DistantPixels CarvePipeline::DistantFound() const {
  DistantPixels found = run_.distant;
  found.masks.clear();
  found.factors.clear();
  found.rays = distant_rays_;
  return found;
}

}  // namespace raycarve
