#include "plugin/carve_flags.h"

#include <cstdlib>
#include <cmath>
#include <sstream>

#include "calib/input_error.h"
#include "carve/surface_evidence.h"

namespace raycarve {
namespace {

// A default as the help prints it: 30, 0.5.
std::string Number(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

void AddPhotoFlags(OptionParser* parser, CarveRequest* request, CarveFlagText* text) {
  parser->BeginGroup("Photos and masks");
  parser->AddDefault("skip_missing_images", &request->view_options.skip_missing_images,
                     "skip registered images whose photo is missing instead of failing");
  parser->AddDefault("max_image_size", &request->view_options.max_image_size,
                     "photos longer than this on their longer side are scaled down to it, their "
                     "cameras with them, as COLMAP's --max_image_size (about 14 bytes a pixel are "
                     "held while carving: 200 photos at 2400 take ~12 GB); <= 0: full size");
  parser->AddDefault("colour_calibration", &request->colour_calibration,
                     "estimate a gain and offset per photo and channel from the sparse points' "
                     "colours (Ceres, robust) and correct the photos before carving: 1 always, "
                     "auto where the correction at least halves the points' colour spread across "
                     "photos (different exposures), 0 never",
                     {"auto", "1", "0", "true", "false"});
  parser->AddDefault("mask_path", &request->view_options.mask_path,
                     "folder of object masks (<photo name>.png, non-zero = object): background "
                     "pixels are left out, and the silhouettes pre-carve the volume");
  parser->AddDefault("background_colour", &text->background,
                     "without --mask_path, masks from a plain backdrop: auto (a photo whose border "
                     "is one to five plain colours, behind an optional frame, gets a mask; natural "
                     "scenes are left as they are), none, or R,G,B");
  parser->AddDefault("background_tolerance", &request->view_options.background.tolerance,
                     "RGB distance from the backdrop colour beyond which a pixel is object");
  parser->AddDefault("mask_graph_cut", &request->view_options.background.refine,
                     "auto masks: refine the colour rule by a graph cut (GrabCut) seeded with the "
                     "sparse points; 0: the colour rule alone");
  parser->AddDefault("agree_masks", &request->agree_masks,
                     "masks from the backdrop: where a photo's mask leaves out what 2+ others "
                     "agree is object (well inside their hull's outline, in the colour they see "
                     "there), it becomes object");
  parser->AddDefault("visual_hull", &request->options.visual_hull,
                     "with masks, carve the silhouettes' visual hull before colouring");
}

void AddCarvingFlags(OptionParser* parser, CarveRequest* request, CarveFlagText* text) {
  parser->BeginGroup("Carve");
  parser->AddDefault("resolution", &request->options.resolution,
                     "voxels along the longest axis of the volume");
  parser->AddDefault("min_voxel_pixels", &request->min_voxel_pixels,
                     "refuse a --resolution whose voxels span fewer pixels of the photos than "
                     "this (median at the volume's centre; finer than the photos resolve, the "
                     "carve degrades); 0: never refuse");
  parser->AddDefault("threshold", &text->threshold,
                     "largest consistent error, RGB units 0-255; auto: per level of detail from "
                     "the reliable sparse points: with masks the --auto_threshold_quantile of "
                     "their voxels' errors, without masks the weighted equal error against the "
                     "voxels just in front (" + Number(kFallbackThreshold) + " where fewer than " +
                         std::to_string(kMinThresholdPoints) + " can be judged)");
  parser->AddDefault("auto_threshold_quantile", &request->options.auto_threshold_quantile,
                     "with --threshold auto and masks: the share of the voxels on sparse points "
                     "that the threshold keeps");
  parser->AddDefault("consistency", &text->consistency,
                     "photo-consistency test: the seed paper's mean colours, Seitz and Dyer's "
                     "standard deviation, or ncc (mean colours, and where the photos see texture "
                     "the normalised cross-correlation of the voxel's patch in every view)",
                     {"mean_colour", "standard_deviation", "ncc"});
  parser->AddDefault("pattern_threshold", &text->pattern_threshold,
                     "with --consistency ncc: carve a textured voxel when 1 - NCC of its "
                     "patterns exceeds this (0-2); auto: per level from the sparse points, by "
                     "--threshold auto's rule, also when --threshold is a number (" +
                         Number(kFallbackPatternThreshold) + " where too few can be judged)");
  parser->AddDefault("protect_surface_points", &request->options.protect_surface_points,
                     "never carve a voxel holding a reliable sparse point (track of 2 or more "
                     "photos, error <= 1 px) by colour: stops carving that runs away");
  parser->AddDefault("free_space_margin", &request->options.free_space_margin_voxels,
                     "carve the sight lines from each photo to the reliable sparse points it saw "
                     "(empty space), stopping this many voxels short of the point; 0: off");
  parser->AddDefault("hold_ground", &request->hold_ground,
                     "without masks, where the sparse points show a plane the subject stands on "
                     "(a floor, a table top): keep what lies under it, where its points are, "
                     "solid (colour carving never opens the floor)");
  parser->AddDefault("distant_free_space", &request->distant_free_space,
                     "without masks, where a photo's pattern moves between the photos as "
                     "something beyond the volume would (sky, clouds, far hills), its rays saw "
                     "across the volume: carve them before colouring (stopping short of sparse "
                     "points seen there)");
  parser->AddDefault("ground_free_space", &request->ground_free_space,
                     "without masks, where the ground is held: where a photo's pattern moves "
                     "between the photos as the ground's plane does (and as nothing in front of "
                     "it would), its rays saw the floor: carve them before colouring, down to "
                     "the band of the ground plane's sparse points");
  parser->AddDefault("floater_expected_points", &request->options.unsupported_component_points,
                     "carve a piece of the model (26-connected, under a quarter of the largest) "
                     "that holds no reliable sparse point where the points' density on the model "
                     "predicts at least this many; 0: keep every piece");
  parser->AddDefault("repair_silhouettes", &request->options.repair_silhouettes,
                     "with masks: after carving, give each photo's object pixels back the model "
                     "that carving took from their rays (a membrane across holes the masks "
                     "contradict)");
  parser->AddDefault("adaptive_threshold", &request->options.adaptive_threshold,
                     "raise the threshold by this times the voxel's within-view colour spread "
                     "(texture edges); 0: a fixed threshold");
  parser->AddDefault("spread_floor", &text->spread_floor,
                     "hold the threshold to at least this times the voxel's within-view colour "
                     "spread (a voxel across a texture edge: its photos disagree by up to that at "
                     "the true surface); 0: no floor; auto: " + Number(kAutoSpreadFloor) +
                         " with --threshold auto on an object capture without masks (cameras "
                         "around it), else 0");
  parser->AddDefault("threshold_views", &text->threshold_views,
                     "with --threshold auto, the photos that judge each sparse point when the "
                     "threshold is measured: tracks (the photos that matched it), seen (every "
                     "photo that sees it through a first pass of the coarsest level) or auto "
                     "(seen on an object capture without masks, cameras around it; else tracks)");
  parser->AddDefault("min_views", &request->options.min_views,
                     "views a voxel must be seen by to be judged");
  parser->AddDefault("min_coverage", &request->options.min_coverage,
                     "judge a voxel only when --min_views views each see at least this share of "
                     "its projected outline (not through a small hole); 0: any pixel counts");
  parser->AddDefault("min_component_voxels", &request->options.min_component_voxels,
                     "after carving, carve every connected piece of fewer solid voxels than this "
                     "(specks in empty space) and carry on carving behind them; 0: keep all");
}

// The carve's machinery (the seed paper's variants and the memory limit), in the "Carve" group.
void AddCarveMethodFlags(OptionParser* parser, CarveRequest* request, CarveFlagText* text) {
  parser->AddDefault("method", &text->method,
                     "visibility: ray casting (the seed paper), or its baselines GVC (item "
                     "buffers, passes) and GVC-LDI (layered depth images)",
                     {"ray", "gvc", "gvc_ldi"});
  parser->AddDefault("vis_lookup", &text->vis_lookup,
                     "how Vis(V) finds its rays: the paper's footprint scan, or per-voxel ray "
                     "lists (same result, more memory)",
                     {"footprint", "ray_lists"});
  parser->AddDefault("order", &text->order,
                     "order of the voxels to judge: first in first out, or most visible pixels "
                     "first",
                     {"fifo", "visible_pixels"});
  parser->AddDefault("decision", &text->decision,
                     "carve when the error exceeds --threshold, or when carving lowers the "
                     "reprojection error of the pixels involved (ray casting only)",
                     {"threshold", "reprojection"});
  parser->AddDefault("max_memory_gib", &request->options.max_memory_gib,
                     "refuse grids whose carving structures would need more (GiB)");
}

void AddLevelFlags(OptionParser* parser, CarveRequest* request) {
  parser->BeginGroup("Levels of detail");
  parser->AddDefault("lod_levels", &request->options.lod_levels,
                     "levels of detail: carve at resolution / 2^(L-1) first, then refine (the "
                     "resolution must be divisible by 2^(L-1)); 1: no levels; 0: as many as "
                     "keep the coarsest level at 64 voxels or more (128: 2, 256: 3)");
  parser->AddDefault("lod_band", &request->options.lod_band,
                     "voxels put back around what survived a coarse level before refining");
  parser->AddDefault("lod_carve_depth", &request->options.lod_carve_depth,
                     "a finer level carves at most this many coarse voxels into what the "
                     "coarser level kept (it refines the surface, it does not dig through it); "
                     "0: no limit");
  parser->AddDefault("lod_reduce_images", &request->options.lod_reduce_images,
                     "coarse levels carve photos reduced by the level's voxel scale (block "
                     "means): a voxel covers about as many pixels at every level");
  parser->AddDefault("supersample", &request->options.supersample,
                     "rays per pixel side at the final level: the photos enlarged (bilinear) so "
                     "that a voxel finer than a pixel is still crossed by rays of every view "
                     "that sees it; 1: the photos as they are; 0: as many (1, 2 or 4) as make a "
                     "voxel span 1.5 rays");
  parser->AddDefault("lod_threshold_scale", &request->options.lod_threshold_scale,
                     "a level whose voxels are 2^k times the final ones judges with threshold x "
                     "this^k (coarse voxels straddle more texture; only the final level uses "
                     "--threshold as given)");
}

void AddMeshFlags(OptionParser* parser, CarveRequest* request) {
  parser->BeginGroup("Mesh and cloud");
  parser->AddDefault("mesh", &request->mesh_kind,
                     "mesh.ply: a smooth welded surface coloured from the photos, or the voxels' "
                     "faces in their mean colours",
                     {"smooth", "voxels"});
  parser->AddDefault("cloud_min_views", &request->cloud_min_views,
                     "smooth mesh: cloud.ply keeps the surface that at least this many photos see "
                     "(COLMAP's fusion asks 5 by default); the mesh keeps everything");
  parser->AddDefault("mesh_edge_pixels", &request->mesh.edge_pixels,
                     "smooth mesh: split edges longer than this many photo pixels, so colours "
                     "keep the photos' detail (0: no splitting)");
  parser->AddDefault("mesh_max_faces", &request->mesh_max_faces,
                     "smooth mesh: at most this many triangles, by decimation (0: no budget)");
  parser->AddDefault("mesh_smoothing_iterations", &request->mesh.smoothing_iterations,
                     "smooth mesh: windowed-sinc smoothing passes (0: the stair-stepped surface)");
  parser->AddDefault("mesh_refine_passes", &request->mesh.refine_passes,
                     "smooth mesh: at most this many passes moving vertices along their normals "
                     "(up to a voxel each) to where the photos agree best (0: none)");
  parser->AddDefault("mesh_refine_converged", &request->mesh.refine_converged_voxels,
                     "smooth mesh: the refinement stops after a pass that moves the vertices by "
                     "less than this many voxels on average (0: run every pass)");
  parser->AddDefault("mesh_refine_search_pixels", &request->mesh.refine_search_pixels,
                     "smooth mesh: each refinement pass searches a voxel either side; on a grid "
                     "finer than the photos (a voxel under a pixel), this many photo pixels "
                     "where further (0: a voxel always)");
  parser->AddDefault("mesh_final_smoothing", &request->mesh.final_smoothing_iterations,
                     "smooth mesh: after refinement, windowed-sinc passes that smooth each vertex "
                     "by the share the photos leave open (none where a clear cost minimum pins "
                     "it; all over plain surfaces and where fewer than two photos see it); 0: "
                     "none");
  parser->AddDefault("mesh_part_min_views", &request->mesh.part_min_views,
                     "smooth mesh: a part of the mesh (a connected piece) stays only where this "
                     "many masked photos need it (half or more of what it covers in the photo is "
                     "object that no other part covers); the largest part always stays; 0: keep "
                     "every part");
  parser->AddDefault("mesh_silhouette_passes", &request->mesh.silhouette_passes,
                     "smooth mesh: after the final smoothing, passes pulling the outline's "
                     "vertices that stand beyond the masks in onto the masks' edges (the median "
                     "over the photos; at most a voxel a pass); 0: none");
  parser->AddDefault("mesh_level_support", &request->level_support,
                     "smooth mesh: where the sparse points show a plane the subject stands on (a "
                     "table, a floor, a mat), level the mesh within two voxels of it (on a grid "
                     "finer than the default, two of the default grid's) onto the plane (a thin "
                     "top's underside half a voxel under it), where its points are; "
                     "0: as carved and refined");
  parser->AddDefault("mesh_remove_box_walls", &request->mesh.remove_grid_walls,
                     "smooth mesh: leave out the surface on the volume box's walls (where the box "
                     "cuts the scene, e.g. a table or the ground running on beyond it, or a "
                     "backdrop seen through it); the mesh is open there. With it, the surface "
                     "fewer than two photos' frames hold and, on a scene (cameras facing one "
                     "way), the surface fewer than two photos see behind the subjects (but for "
                     "a voxel next to what they see) are left out too. 0: keep it all, the mesh "
                     "closed by the box");
  parser->AddDefault("mesh_undo_self_intersections", &request->mesh.undo_self_intersections,
                     "smooth mesh: where refinement and smoothing made triangles pass through "
                     "each other, move their vertices back towards the surface before "
                     "refinement, so that the mesh bounds a solid; 0: the mesh as refined");
  parser->AddDefault("mesh_texture", &request->mesh.texture,
                     "smooth mesh: a texture atlas from the photos (each triangle from the photo "
                     "that sees it best, at the photo's resolution), written as mesh.obj + "
                     "mesh.mtl + mesh_texture.png and inside mesh.glb, and drawn by holdout; 0: "
                     "vertex colours only (mesh.ply always has them)");
}

void AddThreadFlags(OptionParser* parser, CarveRequest* request) {
  parser->BeginGroup("Threads");
  parser->AddDefault("num_threads", &request->options.num_threads,
                     "threads for ray casting and colouring (-1: one per core, at most one per "
                     "photo); the carving is identical for any count");
  parser->AddDefault("batch_voxels", &request->options.batch_voxels,
                     "voxels judged at once (on every thread) against the rays as they stand, "
                     "then carved together; 1: the seed paper's one voxel at a time");
  parser->AddDefault("incremental_statistics", &request->options.incremental_statistics,
                     "ray casting: keep per-voxel colour sums as rays arrive instead of gathering "
                     "Vis(V)'s pixels at every evaluation (same carving)");
}

}  // namespace

const char* const kBasicCarveFlags[10] = {"workspace_path", "output_path",    "resolution",
                                          "threshold",      "mask_path",      "background_colour",
                                          "bbox",           "max_image_size", "mesh",
                                          "num_threads"};

void AddWorkspaceFlags(OptionParser* parser, const WorkspaceFlags& flags) {
  parser->BeginGroup("Workspace");
  parser->AddDefault("workspace_path", flags.workspace_path,
                     "COLMAP project (sparse/0 or sparse or dense/sparse, with images/)");
  parser->AddDefault("input_path", flags.input_path, "model folder, overriding the workspace's");
  if (flags.model_index != nullptr) {
    parser->AddDefault("model_index", flags.model_index,
                       "with several models in sparse/ (from colmap mapper): use sparse/<index>; "
                       "-1: the one with the most registered images");
  }
  parser->AddDefault("image_path", flags.image_path, "photo folder, overriding the workspace's");
  if (flags.output_path != nullptr) {
    parser->AddDefault("output_path", flags.output_path,
                       "output folder (default <workspace>/raycarve)");
  }
}

void AddBoundsFlags(OptionParser* parser, BoundsRequest* bounds) {
  parser->BeginGroup("Bounds");
  parser->AddDefault("capture", &bounds->capture,
                     "what the photos show, for the volume's box: object (the box around the "
                     "sparse points framed where the cameras' axes meet), scene (every sparse "
                     "point the filters below keep), auto: object when the cameras stand around a "
                     "point and the photos have no masks; with masks (unless scene), the box "
                     "narrowed to the masks' visual hull where the sparse points are",
                     {"auto", "object", "scene"});
  parser->AddDefault("min_track_length", &bounds->options.min_track_length,
                     "sparse points seen in fewer images are ignored when bounding the volume");
  parser->AddDefault("max_reprojection_error", &bounds->options.max_reprojection_error,
                     "sparse points with a larger mean reprojection error (px) are ignored; "
                     "<= 0 keeps all");
  parser->AddDefault("min_framed_share", &bounds->options.min_framed_share,
                     "sparse points framed by fewer photos than this share of the best framed "
                     "points' count are the room around the object, left out when they are more "
                     "than twice --trim_fraction of the points (0 keeps all)");
  parser->AddDefault("trim_fraction", &bounds->options.trim_fraction,
                     "fraction of points dropped at each end of each axis (outliers)");
  parser->AddDefault("min_points", &bounds->options.min_points,
                     "fewest usable sparse points that may bound the volume (else --bbox is asked for)");
  parser->AddDefault("margin", &bounds->options.margin,
                     "added on every side, as a fraction of the largest extent");
  parser->AddDefault("bbox", &bounds->bbox,
                     "explicit volume min_x,min_y,min_z,max_x,max_y,max_z (world units); "
                     "overrides the sparse points");
}

void AddCarveFlags(OptionParser* parser, CarveRequest* request, CarveFlagText* text) {
  text->consistency = ConsistencyMethodToString(request->options.consistency);
  text->vis_lookup = VisLookupToString(request->options.vis_lookup);
  text->method = CarveMethodToString(request->options.method);
  text->order = CarveOrderToString(request->options.order);
  text->decision = CarveDecisionToString(request->options.decision);
  AddWorkspaceFlags(parser, {&request->workspace_path, &request->input_path, &request->image_path,
                             &request->output_path, &request->model_index});
  parser->AddDefault("wait", &request->wait_for_output,
                     "when another raycarve run is writing into the output folder, wait for it "
                     "to end instead of stopping");
  AddPhotoFlags(parser, request, text);
  AddBoundsFlags(parser, &request->bounds);
  AddCarvingFlags(parser, request, text);
  AddCarveMethodFlags(parser, request, text);
  AddLevelFlags(parser, request);
  AddMeshFlags(parser, request);
  AddThreadFlags(parser, request);
  parser->BeginGroup("");
}

void ApplyCarveFlags(const OptionParser& parser, const CarveFlagText& text, CarveRequest* request) {
  request->resolution_given = parser.IsSet("resolution");
  if (text.pattern_threshold == "auto") {
    request->options.auto_pattern_threshold = true;
    request->options.pattern_threshold = kFallbackPatternThreshold;
  } else {
    char* end = nullptr;
    const double value = std::strtod(text.pattern_threshold.c_str(), &end);
    if (text.pattern_threshold.empty() || end == nullptr || *end != '\0' ||
        !(value >= 0.0 && value <= 2.0)) {
      throw InputError("--pattern_threshold: must be a number in [0, 2] or auto, got '" +
                       text.pattern_threshold + "'");
    }
    request->options.auto_pattern_threshold = false;
    request->options.pattern_threshold = value;
  }
  if (text.threshold == "auto") {
    request->options.auto_threshold = true;
    request->options.threshold = kFallbackThreshold;
  } else {
    char* end = nullptr;
    const double value = std::strtod(text.threshold.c_str(), &end);
    if (text.threshold.empty() || end == nullptr || *end != '\0' || !std::isfinite(value) ||
        value < 0.0) {
      throw InputError("--threshold: threshold must be a finite number >= 0 (0: no voxel is "
                       "consistent) or auto, got '" + text.threshold + "'");
    }
    request->options.auto_threshold = false;
    request->options.threshold = value;
  }
  if (text.spread_floor == "auto") {
    request->auto_spread_floor = true;
    request->options.spread_floor = 0.0;
  } else {
    char* end = nullptr;
    const double value = std::strtod(text.spread_floor.c_str(), &end);
    if (text.spread_floor.empty() || end == nullptr || *end != '\0' || !std::isfinite(value) ||
        value < 0.0) {
      throw InputError("--spread_floor: must be a finite number >= 0 or auto, got '" +
                       text.spread_floor + "'");
    }
    request->auto_spread_floor = false;
    request->options.spread_floor = value;
  }
  if (text.threshold_views == "auto" || text.threshold_views == "seen" ||
      text.threshold_views == "tracks") {
    request->auto_threshold_views = text.threshold_views == "auto";
    request->options.threshold_seen_views = text.threshold_views == "seen";
  } else {
    throw InputError("--threshold_views: must be auto, seen or tracks, got '" +
                     text.threshold_views + "'");
  }
  ConsistencyMethodFromString(text.consistency, &request->options.consistency);
  VisLookupFromString(text.vis_lookup, &request->options.vis_lookup);
  CarveMethodFromString(text.method, &request->options.method);
  CarveOrderFromString(text.order, &request->options.order);
  CarveDecisionFromString(text.decision, &request->options.decision);
  request->view_options.background.mode =
      ParseBackground(text.background, &request->view_options.background.colour);
  request->background = text.background;
  FinishCarveRequest(request);
}

}  // namespace raycarve
