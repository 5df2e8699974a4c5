// raycarve carve: the carve pipeline at the command line's options, and its summary.
#include <cstdio>
#include <string>
#include <vector>

#include "calib/input_error.h"
#include "pipeline/carve_pipeline.h"
#include "pipeline/carve_summary.h"
#include "plugin/carve_flags.h"
#include "plugin/commands.h"
#include "plugin/option_parser.h"
#include "plugin/progress_display.h"

namespace raycarve {

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
  parser.SetBasicOptions(std::vector<std::string>(std::begin(kBasicCarveFlags), std::end(kBasicCarveFlags)));
  parser.AddExample("raycarve carve --workspace_path P",
                    "the defaults, meant for real photos: outputs in P/raycarve/");
  parser.AddExample("raycarve carve --workspace_path P --resolution 256 --mask_path P/masks",
                    "finer voxels, your own masks (<photo name>.png, non-zero = object)");
  parser.AddExample("raycarve carve --workspace_path P --bbox -1,-1,0,1,1,1.5 --background_colour none",
                    "an explicit volume, no masks (a scene without a plain backdrop)");
  if (!parser.Parse(argc, argv)) return 0;
  ApplyCarveFlags(parser, text, &request);

  ProgressDisplay display;
  PipelineScope scope;
  scope.progress = [&display](const CarveProgress& p) { display.Update(p); };
  scope.progress_end = [&display] { display.Finish(); };
  CarvePipeline pipeline(request, scope);
  const CarveRun& run = pipeline.Run();
  std::fputs(CarveSummaryText(request, run).c_str(), stdout);
  return 0;
}

}  // namespace raycarve
