// raycarve holdout: the carve pipeline without every k-th photo, scored in those photos.
#include <cstdio>
#include <string>

#include "pipeline/holdout_evaluation.h"
#include "plugin/carve_flags.h"
#include "plugin/commands.h"
#include "plugin/option_parser.h"

namespace raycarve {
namespace {

// The table of held-out views and the means.
void PrintEvaluation(const HoldoutEvaluation& evaluation) {
  std::printf("%-24s %10s %8s %12s %10s %16s\n", "held-out view", "PSNR dB", "SSIM",
              "scored px", "sil. IoU", "block PSNR dB");
  for (const HeldOutViewScore& view : evaluation.views) {
    std::printf("%-24s %10.2f %8.3f %12d %10.3f %10.2f (%dx%d)\n", view.name.c_str(),
                view.score.psnr, view.score.ssim, view.score.scored_pixels,
                view.score.silhouette_iou, view.block_psnr, view.block, view.block);
  }
  const bool masks = evaluation.iou_views > 0;
  std::printf("mean over %zu held-out views: PSNR %.2f dB, SSIM %.3f, silhouette IoU %s\n"
              "block PSNR: each photo against its own means over blocks a voxel wide, on the "
              "object: about the most one colour per voxel can score (mean %.2f dB)\n"
              "wrote %s/holdout.json, sparse_depth.csv (each sparse point's verdict), "
              "<view>.png (photo | render | error x4)%s\n",
              evaluation.views.size(), evaluation.mean_psnr, evaluation.mean_ssim,
              masks ? std::to_string(evaluation.mean_iou).c_str() : "n/a (no masks)",
              evaluation.mean_block_psnr, evaluation.output_folder.c_str(),
              evaluation.wrote_mesh ? " and mesh.ply" : "");
  const exporter::SparseDepthAgreement& depth = evaluation.sparse_depth;
  if (depth.points > 0) {
    std::printf("sparse points the held-out photos saw (%d, triangulated from 2+ other photos, "
                "inside the volume): %.1f%% drawn at their depth (within 2 voxels), %.1f%% hidden "
                "behind something nearer, %.1f%% in front of the model (a hole there), %.1f%% "
                "where nothing is drawn\n",
                depth.points, 100.0 * depth.AtDepthShare(), 100.0 * depth.HiddenShare(),
                100.0 * depth.BehindShare(), 100.0 * depth.UndrawnShare());
  }
  if (evaluation.wrote_mesh) {
    std::printf("the voxel volume drawn into the same views: PSNR %.2f dB, silhouette IoU %s "
                "(the mesh: %+.2f dB)\n",
                evaluation.mean_volume_psnr,
                masks ? std::to_string(evaluation.mean_volume_iou).c_str() : "n/a (no masks)",
                evaluation.mean_psnr - evaluation.mean_volume_psnr);
  }
}

}  // namespace

int RunHoldout(int argc, char** argv) {
  CarveRequest request;
  CarveFlagText text;
  HoldoutOptions options;
  OptionParser parser(
      "holdout",
      "Held-out evaluation: carves the project without every k-th view, renders the carved model "
      "into the left-out views, and reports PSNR and SSIM (over the rendered and the true "
      "silhouette where there is a mask, else over the whole photo), silhouette IoU and the share "
      "of the views' sparse points drawn at their depth; writes photo | render | error images to "
      "<output>/holdout/, holdout.json and sparse_depth.csv.");
  AddCarveFlags(&parser, &request, &text);
  parser.BeginGroup("Held-out photos");
  parser.AddDefault("every", &options.every, "leave out views 1, 1 + k, 1 + 2k, ... (k >= 2)");
  parser.AddDefault("render", &options.render,
                    "how the model is drawn: the smooth mesh coloured from the training photos "
                    "(what carve writes as mesh.ply), the carved volume (a ray per pixel to the "
                    "first solid voxel, in its colour) or the cloud's points as square splats",
                    {"mesh", "volume", "splats"});
  parser.AddDefault("model", &options.model_path,
                    "score this model instead of carving, on the same held-out views: a PLY "
                    "mesh or cloud (COLMAP's fused.ply, a mesh with vertex colours) or a glTF "
                    "or OBJ mesh drawn with its texture (.glb, .gltf, .obj: raycarve's mesh.glb "
                    "or mesh.obj, another tool's)");
  parser.AddDefault("point_size", &options.point_size,
                    "splat side (world units) for a cloud given by --model (0: 1.5 x the cloud's "
                    "median neighbour spacing)");
  parser.AddDefault("score_mask_path", &options.score_mask_path,
                    "score the held-out views against these masks (<photo name>.png, as "
                    "--mask_path) instead of the masks the carve uses: to compare automatic "
                    "masks with exact ones on the same footing");
  parser.SetBasicOptions({"workspace_path", "output_path", "every", "render", "model",
                          "score_mask_path", "resolution", "mask_path", "num_threads"});
  parser.AddExample("raycarve holdout --workspace_path P",
                    "carve without every 4th photo at carve's defaults; score the mesh in those photos");
  parser.AddExample("raycarve holdout --workspace_path P --model P/dense/fused.ply",
                    "score another model (COLMAP's fused cloud) on the same held-out photos");
  if (!parser.Parse(argc, argv)) return 0;
  ApplyCarveFlags(parser, text, &request);
  PrintEvaluation(EvaluateHeldOutViews(request, options));
  return 0;
}

}  // namespace raycarve
