#pragma once

#include <string>
#include <vector>

#include "export/holdout_score.h"
#include "pipeline/carve_request.h"

namespace raycarve {

// `raycarve holdout`: the carve pipeline without every k-th photo, the model drawn into the
// left-out photos and scored there.
struct HoldoutOptions {
  int every = 4;                // photos 1, 1 + k, 1 + 2k, ... in name order are held out (k >= 2)
  std::string render = "mesh";  // "mesh" (coloured from the training photos), "volume", "splats"
  std::string model_path;       // score this PLY mesh or cloud instead of carving
  double point_size = 0.0;      // splat side for a cloud given by model_path (0: from its spacing)
  std::string score_mask_path;  // score against these masks instead of the carve's
};

// One held-out photo's scores.
struct HeldOutViewScore {
  std::string name;
  exporter::HoldoutScore score;         // the model as drawn
  exporter::HoldoutScore volume_score;  // the voxel volume (the mesh's source), or `score`
  int uncoloured_pixels = 0;            // --render volume: solid voxels no photo coloured
  int block = 1;                        // block PSNR's block side, pixels (about a voxel)
  double block_psnr = 0.0;              // the photo against its own block means
  // The model's depth against the sparse points this view saw (inside the volume, triangulated
  // from two or more other photos), within two voxels.
  exporter::SparseDepthAgreement sparse_depth;
  std::vector<exporter::SparsePointDepth> sparse_points;  // each point counted, with its verdict
};

struct HoldoutEvaluation {
  std::string render;    // as drawn (a cloud given by model_path is drawn as splats)
  bool carved = false;   // false: model_path was scored
  bool wrote_mesh = false;
  std::vector<HeldOutViewScore> views;  // in name order
  double mean_psnr = 0.0;
  double mean_ssim = 0.0;
  int iou_views = 0;             // views with a mask (silhouette IoU)
  double mean_iou = -1.0;        // -1: no masks
  double mean_block_psnr = 0.0;
  double mean_volume_psnr = 0.0;
  double mean_volume_iou = -1.0;
  // Over every held-out view's sparse points together (SparseDepthAgreement).
  exporter::SparseDepthAgreement sparse_depth;
  double sparse_depth_tolerance = 0.0;  // two voxels, in the model's units
  std::string output_folder;  // <output>/holdout: holdout.json, sparse_depth.csv, <view>.png, mesh.ply
};

// Loads the project holding out every options.every-th photo (their sparse observations too),
// carves and meshes the rest through CarvePipeline (or reads options.model_path), draws the model
// into the held-out photos and scores it; writes holdout.json and photo | render | error images
// to <output>/holdout/ as a set. Throws InputError on bad input or options.
HoldoutEvaluation EvaluateHeldOutViews(const CarveRequest& request, const HoldoutOptions& options);

}  // namespace raycarve
