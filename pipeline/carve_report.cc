#include "pipeline/carve_report.h"

#include <algorithm>

#include <sys/resource.h>

#include "pipeline/json_writer.h"
#include "pipeline/run_info.h"

namespace raycarve {
namespace {

// Each section of report.json, in the order they are written.

void WriteOptions(const CarveRequest& request, const CarveRun& run, JsonWriter& json) {
  json.Key("options").BeginObject()
      .Key("method").Value(CarveMethodToString(request.options.method))
      .Key("resolution").Value(request.options.resolution)
      .Key("consistency").Value(ConsistencyMethodToString(request.options.consistency))
      .Key("threshold").Value(request.options.auto_threshold ? std::string("auto")
                                                              : std::to_string(request.options.threshold))
      .Key("auto_threshold_quantile").Value(request.options.auto_threshold_quantile)
      .Key("pattern_threshold").Value(request.options.auto_pattern_threshold ? std::string("auto") : std::to_string(request.options.pattern_threshold))
      .Key("protect_surface_points").Value(request.options.protect_surface_points)
      .Key("free_space_margin").Value(request.options.free_space_margin_voxels)
      .Key("hold_ground").Value(request.hold_ground)
      .Key("distant_free_space").Value(request.distant_free_space)
      .Key("floater_expected_points").Value(request.options.unsupported_component_points)
      .Key("repair_silhouettes").Value(request.options.repair_silhouettes)
      .Key("adaptive_threshold").Value(request.options.adaptive_threshold)
      .Key("spread_floor").Value(run.spread_floor)
      .Key("spread_floor_reason").Value(run.spread_floor_reason)
      .Key("threshold_views").Value(run.threshold_seen_views ? "seen" : "tracks")
      .Key("threshold_views_reason").Value(run.threshold_views_reason)
      .Key("min_views").Value(request.options.min_views)
      .Key("min_coverage").Value(request.options.min_coverage)
      .Key("order").Value(CarveOrderToString(request.options.order))
      .Key("decision").Value(CarveDecisionToString(request.options.decision))
      .Key("lod_levels").Value(request.options.lod_levels == kAutomaticLevels
                                   ? AutomaticLevels(request.options.resolution)
                                   : request.options.lod_levels)
      .Key("lod_levels_automatic").Value(request.options.lod_levels == kAutomaticLevels)
      .Key("lod_band").Value(request.options.lod_band)
      .Key("lod_carve_depth").Value(request.options.lod_carve_depth)
      .Key("lod_reduce_images").Value(request.options.lod_reduce_images)
      .Key("supersample").Value(request.options.supersample)
      .Key("lod_threshold_scale").Value(request.options.lod_threshold_scale)
      .Key("min_component_voxels").Value(request.options.min_component_voxels)
      .Key("vis_lookup").Value(VisLookupToString(request.options.vis_lookup))
      .Key("num_threads").Value(ResolveNumThreads(request.options.num_threads))
      .Key("batch_voxels").Value(request.options.batch_voxels)
      .Key("incremental_statistics").Value(request.options.incremental_statistics)
      .Key("max_memory_gib").Value(request.options.max_memory_gib)
      .Key("max_image_size").Value(request.view_options.max_image_size)
      .Key("mask_path").Value(request.view_options.mask_path)
      .Key("background").Value(request.background)
      .Key("masks_from_files").Value(run.masks_from_files)
      .Key("masks_from_backdrop").Value(run.masks_from_backdrop)
      .Key("backdrop_masks_dropped").Value(run.backdrop_masks_dropped)
      .Key("background_tolerance").Value(request.view_options.background.tolerance)
      .Key("mask_graph_cut").Value(request.view_options.background.refine)
      .Key("visual_hull").Value(request.options.visual_hull)
      .EndObject();
}

void WriteMasks(const CarveRequest& request, const CarveRun& run, JsonWriter& json) {
  json.Key("masks").BeginArray();
  for (const PhotoMaskInfo& photo : run.mask_photos) {
    json.BeginObject()
        .Key("name").Value(photo.name)
        .Key("source").Value(photo.source)
        .Key("object_share").Value(photo.object_share);
    if (request.background == "auto" && request.view_options.mask_path.empty()) {
      json.Key("backdrop_found").Value(photo.backdrop.found)
          .Key("border_explained").Value(photo.backdrop.explained);
      json.Key("backdrop_colours").BeginArray();
      for (size_t c = 0; c < photo.backdrop.colours.size(); ++c) {
        json.BeginObject()
            .Key("rgb").Value(JsonArray(photo.backdrop.colours[c]))
            .Key("border_share").Value(photo.backdrop.shares[c])
            .EndObject();
      }
      json.EndArray();
      json.Key("object_colours_on_border").BeginArray();
      for (const Eigen::Vector3d& colour : photo.backdrop.object_colours) {
        json.Value(JsonArray(colour));
      }
      json.EndArray();
      json.Key("object_border_share").Value(photo.backdrop.object_border_share);
      json.Key("frame_px").Value(std::vector<double>{
          static_cast<double>(photo.backdrop.frame[0]), static_cast<double>(photo.backdrop.frame[1]),
          static_cast<double>(photo.backdrop.frame[2]), static_cast<double>(photo.backdrop.frame[3])});
      json.Key("sparse_point_seeds").Value(photo.mask.seeds)
          .Key("graph_cut").Value(photo.mask.refined)
          .Key("regions_restored_by_seeds").Value(photo.mask.regions_restored)
          .Key("cut_to_volume").Value(photo.mask.cut_to_box);
    }
    const auto at = std::find(run.view_names.begin(), run.view_names.end(), photo.name);
    if (run.mask_agreement.views > 0 && at != run.view_names.end()) {
      const size_t v = static_cast<size_t>(at - run.view_names.begin());
      json.Key("agreement_added_pixels").Value(run.mask_agreement.added[v]);
    }
    json.EndObject();
  }
  json.EndArray();
  {
    const MaskAgreementStatistics& agreement = run.mask_agreement;
    const double before = std::max<int64_t>(1, agreement.TotalObjectBefore());
    json.Key("mask_agreement").BeginObject()
        .Key("enabled").Value(request.agree_masks)
        .Key("views").Value(agreement.views)
        .Key("hull_voxels").Value(agreement.hull_voxels)
        .Key("added_share").Value(agreement.views > 0 ? agreement.TotalAdded() / before : 0.0)
        .Key("seconds").Value(agreement.seconds)
        .EndObject();
  }
}

void WriteColourCalibration(const CarveRequest& request, const CarveRun& run, JsonWriter& json) {
  if (ColourCalibrationModeOf(request) != ColourCalibrationMode::kOff) {
    json.Key("colour_calibration").BeginObject()
        .Key("mode").Value(request.colour_calibration)
        .Key("applied").Value(run.colour.applied)
        .Key("points_used").Value(run.colour.points_used)
        .Key("observations_used").Value(run.colour.observations_used)
        .Key("spread_before").Value(run.colour.spread_before)
        .Key("spread_after").Value(run.colour.spread_after);
    json.Key("photos").BeginArray();
    for (const ColourCorrection& correction : run.colour.corrections) {
      json.BeginObject()
          .Key("name").Value(correction.name)
          .Key("gain").Value(JsonArray(correction.gain))
          .Key("offset").Value(JsonArray(correction.offset))
          .Key("observations").Value(correction.observations)
          .EndObject();
    }
    json.EndArray();
    json.EndObject();
  }
}

// The volume's box and the resolution the photos support.
void WriteBounds(const CarveRun& run, JsonWriter& json) {
  json.Key("bounds").BeginObject()
      .Key("min").Value(JsonArray(run.bounds.box.min()))
      .Key("max").Value(JsonArray(run.bounds.box.max()))
      .Key("explicit").Value(run.bounds.is_explicit)
      .Key("around_focus").Value(run.bounds.around_focus)
      .Key("around_hull").Value(run.bounds.around_hull)
      .Key("depth_resolved_points").Value(run.bounds.depth_resolved_points)
      .Key("depth_tried_points").Value(run.bounds.depth_tried_points)
      .EndObject();
  json.Key("resolution_support").BeginObject()
      .Key("voxel_pixels").Value(run.voxel_pixels)
      .Key("supported_resolution").Value(run.supported_resolution)
      .Key("default_lowered_from").Value(run.resolution_lowered_from)
      .Key("hull_lowered_from").Value(run.hull_resolution_from)
      .EndObject();
}

// What the capture was found to be: its layout, the supporting plane and the ground held, the
// distant and ground pixels found.
void WriteCapture(const CarveRun& run, JsonWriter& json) {
  const CarveStatistics& s = run.result->statistics;
  const CaptureLayout& layout = run.layout;
  json.Key("capture").BeginObject()
      .Key("kind").Value(std::string(layout.object_centred ? "object" : "scene"))
      .Key("cone_half_angle_degrees").Value(layout.cone_half_angle_degrees)
      .Key("largest_gap_degrees").Value(layout.largest_gap_degrees)
      .Key("focus").Value(JsonArray(layout.focus))
      .Key("camera_distance").Value(layout.camera_distance)
      .Key("focus_in_front").Value(layout.focus_in_front)
      .Key("cameras").Value(layout.cameras)
      .Key("focus_box_points").Value(layout.focus_box_points)
      .Key("occluder_points").Value(layout.occluder_points);
  if (!layout.focus_box.isEmpty()) {
    json.Key("focus_box_min").Value(JsonArray(layout.focus_box.min()))
        .Key("focus_box_max").Value(JsonArray(layout.focus_box.max()));
  }
  const exporter::SupportingPlane& plane = run.plane;
  json.Key("supporting_plane").BeginObject()
      .Key("found").Value(plane.found)
      .Key("normal").Value(JsonArray(plane.normal))
      .Key("offset").Value(plane.offset)
      .Key("tolerance").Value(plane.tolerance)
      .Key("points").Value(plane.points)
      .Key("on_plane_share").Value(plane.on_plane_share)
      .Key("below_share").Value(plane.below_share)
      .Key("cameras_above_share").Value(plane.cameras_above_share)
      .Key("spread_ratio").Value(plane.spread_ratio)
      .Key("found_by_spread").Value(plane.found_by_spread)
      .Key("densest_plane_passed_over").Value(plane.densest_on_share >= 0.0);
  if (plane.densest_on_share >= 0.0) {
    json.Key("densest_plane_on_share").Value(plane.densest_on_share)
        .Key("densest_plane_below_share").Value(plane.densest_below_share)
        .Key("densest_plane_angle_to_photos_up").Value(plane.densest_angle_to_photos_up);
  }
  json.Key("angle_to_photos_up").Value(plane.angle_to_photos_up)
      .Key("photos_up").Value(JsonArray(plane.photos_up.up))
      .Key("photos_up_agreement").Value(plane.photos_up.agreement)
      .Key("photos_turned").Value(plane.photos_up.turned)
      .Key("photos_up_known").Value(plane.photos_up.Known());
  json.Key("ground_held").Value(!run.ground.empty())
      .Key("ground").Value(run.ground_reason)
      .Key("ground_footprint_points").Value(static_cast<int64_t>(run.ground.footprint.size()))
      .Key("ground_reach").Value(run.ground.radius)
      .Key("ground_lone_points_left_out").Value(static_cast<int64_t>(run.ground.lone_points))
      .Key("ground_voxels").Value(s.ground_voxels)
      .Key("beyond_ground_carved").Value(s.beyond_ground_carved)
      .EndObject();
  const DistantPixels& distant = run.distant;
  json.Key("distant_pixels").BeginObject()
      .Key("looked_for").Value(run.distant_reason.empty())
      .Key("reason").Value(run.distant_reason)
      .Key("photos_judged").Value(distant.photos_judged)
      .Key("textured_pixels").Value(distant.textured)
      .Key("found_pixels").Value(distant.distant)
      .Key("nearer_pixels").Value(distant.nearer)
      .Key("plain_region_pixels").Value(distant.grown)
      .Key("plain_region_rays_refused").Value(distant.grown_refused)
      .Key("distant_rays").Value(s.distant_rays)
      .Key("distant_voxels_carved").Value(s.distant_carved)
      .Key("distant_through_ground_not_drawn").Value(s.distant_through_ground)
      .Key("seconds").Value(distant.seconds)
      .EndObject();
  const DistantPixels& ground = run.ground_pixels;
  json.Key("ground_pixels").BeginObject()
      .Key("looked_for").Value(run.ground_pixels_reason.empty())
      .Key("reason").Value(run.ground_pixels_reason)
      .Key("textured_pixels").Value(ground.textured)
      .Key("found_pixels").Value(ground.distant)
      .Key("nearer_pixels").Value(ground.nearer)
      .Key("rays").Value(s.ground_seen_rays)
      .Key("voxels_carved").Value(s.ground_seen_carved)
      .Key("seconds").Value(ground.seconds)
      .EndObject();
  json.EndObject();
}

void WriteStatistics(const CarveRequest& request, const CarveRun& run, JsonWriter& json) {
  const CarveStatistics& s = run.result->statistics;
  WriteBounds(run, json);
  WriteCapture(run, json);
  json.Key("statistics").BeginObject()
      .Key("visibility").Value(s.visibility)
      .Key("grid").Value(std::vector<double>{static_cast<double>(s.dimensions.x()),
                                              static_cast<double>(s.dimensions.y()),
                                              static_cast<double>(s.dimensions.z())})
      .Key("voxel_size").Value(s.voxel_size)
      .Key("num_voxels").Value(s.num_voxels)
      .Key("views_with_masks").Value(s.views_with_masks)
      .Key("silhouette_repair").BeginObject()
          .Key("views").Value(s.silhouette_repair.views)
          .Key("object_pixels").Value(s.silhouette_repair.object_pixels)
          .Key("lost_pixels").Value(s.silhouette_repair.lost_pixels)
          .Key("restored_voxels").Value(s.silhouette_repair.restored_voxels)
          .Key("bridging_voxels").Value(s.silhouette_repair.bridging_voxels)
          .Key("outside_hull_pixels").Value(s.silhouette_repair.outside_hull_pixels)
          .Key("seconds").Value(s.silhouette_repair.seconds)
          .EndObject()
      .Key("visual_hull_carved").Value(s.visual_hull_carved)
      .Key("free_space").BeginObject()
          .Key("margin_voxels").Value(request.options.free_space_margin_voxels)
          .Key("sight_lines").Value(s.free_space_sight_lines)
          .Key("through_ground_not_drawn").Value(s.free_space_through_ground)
          .Key("voxels").Value(s.free_space_carved)
          .Key("voxels_first_level").Value(s.free_space_level0_carved)
          .Key("seconds").Value(s.free_space_seconds)
          .EndObject()
      .Key("component_carved").Value(s.component_carved)
      .Key("floaters").BeginObject()
          .Key("pieces").Value(s.unsupported_components)
          .Key("voxels").Value(s.unsupported_component_carved)
          .Key("largest_expected_points").Value(s.unsupported_largest_expected)
          .EndObject()
      .Key("visual_hull_seconds").Value(s.visual_hull_seconds)
      .Key("initial_surface").Value(s.initial_surface)
      .Key("carved").Value(s.carved)
      .Key("evaluated").Value(s.evaluated)
      .Key("passes").Value(s.passes)
      .Key("threads").Value(s.threads)
      .Key("parallel_seconds").Value(s.parallel_seconds)
      .Key("parallel_runs").Value(s.parallel_runs)
      .Key("inline_runs").Value(s.inline_runs)
      .Key("thread_work_seconds").Value(s.thread_work_seconds)
      .Key("reprojection_error_before").Value(s.reprojection_error_before)
      .Key("reprojection_error_after").Value(s.reprojection_error_after)
      .Key("final_solid").Value(s.final_solid)
      .Key("final_surface").Value(s.final_surface)
      .Key("visible_surface").Value(s.visible_surface)
      .Key("convergence_seconds").Value(s.carve_seconds)
      .Key("peak_memory_bytes").Value(static_cast<uint64_t>(s.peak_memory_bytes))
      .Key("process_peak_resident_mib").Value(ProcessPeakMiB())
      .EndObject();
}

void WriteLevels(const CarveRequest& request, const CarveRun& run, JsonWriter& json) {
  const CarveStatistics& s = run.result->statistics;
  json.Key("levels").BeginArray();
  for (const LevelStatistics& level : s.levels) {
    json.BeginObject()
        .Key("resolution").Value(level.resolution)
        .Key("grid").Value(std::vector<double>{static_cast<double>(level.dimensions.x()),
                                                static_cast<double>(level.dimensions.y()),
                                                static_cast<double>(level.dimensions.z())})
        .Key("image_factor").Value(level.image_factor)
        .Key("image_enlargement").Value(level.image_enlargement)
        .Key("free_space_carved").Value(level.free_space_carved)
        .Key("threshold").Value(level.threshold);
    const bool patterns = request.options.consistency == ConsistencyMethod::kPatchCorrelation;
    if (patterns) json.Key("pattern_threshold").Value(level.pattern_threshold);
    if (level.threshold_given) json.Key("threshold_from_tile_plan").Value(true);
    if (level.threshold_resolution > 0) {
      json.Key("threshold_resolution").Value(level.threshold_resolution);
    }
    if (!level.threshold_given &&
        (request.options.auto_threshold || (patterns && request.options.auto_pattern_threshold))) {
      const ThresholdEstimate& e = level.estimate;
      std::vector<double> surface, front;
      for (int q = 0; q <= 20; ++q) {
        surface.push_back(ThresholdEstimate::Quantile(e.surface_errors, q / 20.0));
        front.push_back(ThresholdEstimate::Quantile(e.front_errors, q / 20.0));
      }
      json.Key("threshold_estimate").BeginObject()
          .Key("from_data").Value(level.threshold_from_data)
          .Key("quantile").Value(e.quantile)
          .Key("points_in_grid").Value(e.points_in_grid)
          .Key("points_judged").Value(e.points_judged)
          .Key("views_per_point").Value(e.ViewsPerPoint())
          .Key("track_views_per_point").Value(e.TrackViewsPerPoint())
          .Key("surface_error_quantiles_0_to_1_by_0_05").Value(surface)
          .Key("front_offset_voxels").Value(ThresholdEstimate::kFrontOffsetVoxels)
          .Key("front_voxels").Value(static_cast<uint64_t>(e.front_errors.size()))
          .Key("front_error_quantiles_0_to_1_by_0_05").Value(front)
          .Key("front_share_above_threshold").Value(e.FrontCarved())
          .EndObject();
    }
    if (level.first_pass_seconds > 0.0) {
      json.Key("first_pass").BeginObject()
          .Key("threshold").Value(level.first_pass_threshold)
          .Key("seconds").Value(level.first_pass_seconds)
          .EndObject();
    }
    json.Key("protected_kept").Value(level.protected_kept)
        .Key("interior_held").Value(level.interior_held)
        .Key("start_solid").Value(level.start_solid)
        .Key("carved").Value(level.carved)
        .Key("evaluated").Value(level.evaluated)
        .Key("final_solid").Value(level.final_solid)
        .Key("seconds").Value(level.seconds)
        .Key("setup_seconds").Value(level.setup_seconds)
        .EndObject();
  }
  json.EndArray();
}

void WriteOutputs(const CarveRequest& request, const CarveRun& run, JsonWriter& json) {
  if (run.has_sparse) {
    const double voxel = run.result->volume.grid().voxel_size();
    json.Key("sparse_points").BeginObject()
        .Key("count").Value(static_cast<uint64_t>(run.sparse.num_reconstruction))
        .Key("within_2_voxels").Value(run.sparse.precision)
        .Key("distance_90_percent_voxels").Value(run.sparse.accuracy / voxel)
        .Key("mean_distance_voxels").Value(run.sparse.mean_reconstruction_to_reference / voxel)
        .Key("reliable_ones_kept_by_known_surface").Value(request.options.protect_surface_points)
        .EndObject();
  }
  if (run.tiled.jobs > 0) {
    const Eigen::Vector3i& t = run.tiled.tiles_per_axis;
    json.Key("tiles").BeginObject()
        .Key("plan_id").Value(run.tiled.plan_id)
        .Key("jobs").Value(run.tiled.jobs)
        .Key("tiles_per_axis").Value(std::vector<double>{double(t.x()), double(t.y()), double(t.z())})
        .Key("overlap_voxels").Value(run.tiled.overlap)
        .Key("merge_evaluated").Value(run.result->statistics.evaluated)
        .EndObject();
  }
  json.Key("stage_seconds").BeginObject();
  for (const auto& [name, seconds] : run.stage_seconds) json.Key(name).Value(seconds);
  json.EndObject();
  json.Key("outputs").BeginObject()
      .Key("cloud").Value("cloud.ply")
      .Key("cloud_visibility").Value(request.mesh_kind == "smooth" ? "cloud.ply.vis" : "")
      .Key("dense_workspace").Value(request.mesh_kind == "smooth" && run.dense_sparse_skipped.empty())
      .Key("dense_workspace_note")
      .Value(request.mesh_kind != "smooth"
                 ? std::string("--mesh voxels: no visibility, no dense workspace")
                 : run.dense_sparse_skipped.empty()
                       ? std::string("fused.ply and fused.ply.vis (cloud.ply and cloud.ply.vis "
                                     "under COLMAP's names) and the sparse model in sparse/")
                       : "sparse/ not written: " + run.dense_sparse_skipped)
      .Key("cloud_points").Value(static_cast<uint64_t>(run.num_cloud_points))
      .Key("cloud_min_views").Value(request.mesh_kind == "smooth" ? request.cloud_min_views
                                                                  : request.options.min_views)
      .Key("mesh").Value("mesh.ply")
      .Key("mesh_glb").Value(request.mesh_kind == "smooth" ? "mesh.glb" : "")
      .Key("mesh_obj").Value(run.mesh_texture.atlas_width > 0 ? "mesh.obj" : "")
      .Key("mesh_kind").Value(request.mesh_kind)
      .Key("mesh_triangles").Value(static_cast<uint64_t>(run.num_mesh_triangles))
      .Key("mesh_vertices").Value(static_cast<uint64_t>(run.num_mesh_vertices))
      .Key("convergence").Value("convergence.csv")
      .Key("preview").Value(request.mesh_kind == "smooth" ? "preview.png" : "")
      .Key("page").Value("report.html")
      .EndObject();
}

void WriteMesh(const CarveRequest& request, const CarveRun& run, JsonWriter& json) {
  if (request.mesh_kind == "smooth") {
    const exporter::MeshTopology& t = run.mesh_topology;
    const exporter::MeshColouringSummary& c = run.mesh_colouring;
    json.Key("mesh").BeginObject()
        .Key("closed_manifold").Value(t.IsClosedManifold())
        .Key("faults").Value(t.Faults())
        .Key("self_intersecting_pairs").Value(static_cast<int64_t>(t.self_intersecting_pairs))
        .Key("undo_self_intersections").Value(request.mesh.undo_self_intersections)
        .Key("texture").Value(request.mesh.texture)
        .Key("textured_triangles").Value(run.mesh_texture.textured)
        .Key("texture_charts").Value(run.mesh_texture.charts)
        .Key("texture_width").Value(run.mesh_texture.atlas_width)
        .Key("texture_height").Value(run.mesh_texture.atlas_height)
        .Key("texture_scale").Value(run.mesh_texture.scale)
        .Key("texture_too_large").Value(run.mesh_texture.too_large)
        .Key("texture_seam_edges").Value(run.mesh_texture.seam_edges)
        .Key("texture_seam_step").Value(run.mesh_texture.seam_step)
        .Key("texture_inner_step").Value(run.mesh_texture.inner_step)
        .Key("self_intersecting_pairs_undone")
        .Value(run.mesh_self_intersections.pairs_before - run.mesh_self_intersections.pairs_after)
        .Key("self_intersection_vertices_moved_back")
        .Value(run.mesh_self_intersections.vertices_moved_back)
        .Key("components").Value(static_cast<int64_t>(t.components))
        .Key("small_components_removed").Value(run.mesh_small_components_removed)
        .Key("grid_wall_vertices").Value(run.mesh_grid_wall_vertices)
        .Key("remove_box_walls").Value(request.mesh.remove_grid_walls)
        .Key("box_wall_triangles_removed").Value(run.mesh_wall_triangles_removed)
        .Key("beyond_frames_triangles_removed").Value(run.mesh_uncovered_triangles_removed)
        .Key("unseen_triangles_removed").Value(run.mesh_unseen_triangles_removed)
        .Key("unseen_vertices_kept").Value(run.mesh_unseen_vertices_kept)
        .Key("box_wall_share").Value(run.WallShare())
        .Key("boundary_edges").Value(static_cast<int64_t>(t.boundary_edges))
        .Key("non_manifold_edges").Value(static_cast<int64_t>(t.non_manifold_edges))
        .Key("non_manifold_vertices").Value(static_cast<int64_t>(t.non_manifold_vertices))
        .Key("edge_pixels").Value(request.mesh.edge_pixels)
        .Key("max_faces").Value(static_cast<int64_t>(request.mesh.max_triangles))
        .Key("smoothing_iterations").Value(request.mesh.smoothing_iterations)
        .Key("refine_passes").Value(request.mesh.refine_passes)
        .Key("refine_converged_voxels").Value(request.mesh.refine_converged_voxels)
        .Key("refine_search_pixels").Value(request.mesh.refine_search_pixels)
        .Key("refinement_search_voxels")
        .Value(run.mesh_refinement.search_range / run.result->volume.grid().voxel_size())
        .Key("refinement_passes").Value(run.mesh_refinement.passes)
        .Key("refinement_last_mean_abs_offset_voxels")
        .Value(run.mesh_refinement.last_mean_abs_offset / run.result->volume.grid().voxel_size())
        .Key("refinement_vertices_moved").Value(run.mesh_refinement.moved)
        .Key("refinement_mean_abs_offset_voxels")
        .Value(run.mesh_refinement.mean_abs_offset / run.result->volume.grid().voxel_size())
        .Key("refinement_mean_pinned").Value(run.mesh_refinement.mean_pinned)
        .Key("final_smoothing_iterations").Value(request.mesh.final_smoothing_iterations)
        .Key("final_smoothing_mean_move_voxels")
        .Value(run.mesh_final_smoothing_mean_move / run.result->volume.grid().voxel_size())
        .Key("part_min_views").Value(request.mesh.part_min_views)
        .Key("parts_before").Value(run.mesh_parts.parts)
        .Key("parts_removed_unneeded").Value(run.mesh_parts.removed)
        .Key("vertices_removed_unneeded").Value(run.mesh_parts.removed_vertices)
        .Key("parts_kept_for_sparse_points").Value(run.mesh_parts.anchored)
        .Key("silhouette_passes").Value(run.mesh_silhouettes.passes)
        .Key("silhouette_outline_vertices").Value(run.mesh_silhouettes.outline_vertices)
        .Key("silhouette_pulled_vertices").Value(run.mesh_silhouettes.pulled_vertices)
        .Key("silhouette_beyond_masks_px_first").Value(run.mesh_silhouettes.mean_outside_pixels_first)
        .Key("silhouette_beyond_masks_px_last").Value(run.mesh_silhouettes.mean_outside_pixels_last)
        .Key("silhouette_mean_move_voxels")
        .Value(run.mesh_silhouettes.mean_move / run.result->volume.grid().voxel_size())
        .Key("level_support").Value(request.level_support)
        .Key("levelled_vertices").Value(run.mesh_levelling.vertices)
        .Key("levelled_mean_move_voxels")
        .Value(run.mesh_levelling.mean_move / run.result->volume.grid().voxel_size())
        .Key("vertices_coloured_from_photos").Value(c.from_photos)
        .Key("vertices_coloured_from_neighbours").Value(c.from_neighbours)
        .Key("vertices_uncoloured").Value(c.uncoloured)
        .Key("share_seen").Value(c.SeenShare())
        .Key("mean_photos_per_vertex").Value(c.mean_views)
        .EndObject();
  }
}

}  // namespace

void WriteRunIdentity(JsonWriter& json) {
  json.Key("schema_version").Value(kReportSchemaVersion)
      .Key("raycarve_version").Value(Version())
      .Key("commit").Value(BuildCommit())
      .Key("command_line").Value(RunCommandLine())
      .Key("start_time").Value(RunStartTime());
  // The units of the figures that follow, by the kind of field (docs/report.md).
  json.Key("units").BeginObject()
      .Key("lengths").Value("the model's world units (COLMAP's frame)")
      .Key("fields_named_voxels").Value("voxels of the finest grid")
      .Key("fields_named_px").Value("photo pixels after --max_image_size")
      .Key("angles").Value("degrees")
      .Key("times").Value("seconds (wall)")
      .Key("memory").Value("bytes, or MiB where the field says mib")
      .Key("colours_and_thresholds").Value("RGB 0-255")
      .Key("shares").Value("fractions 0-1")
      .Key("psnr").Value("dB over 8-bit RGB")
      .EndObject();
}

double ProcessPeakMiB() {
  struct rusage usage {};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  return usage.ru_maxrss / 1024.0;  // Linux counts it in KiB
}

std::string CarveReportJson(const CarveRequest& request, const CarveRun& run) {
  JsonWriter json;
  json.BeginObject();
  WriteRunIdentity(json);
  json.Key("model_path").Value(run.model_path)
      .Key("image_path").Value(run.image_path)
      .Key("num_views").Value(run.num_views)
      .Key("num_missing_images").Value(run.num_missing_images);
  WriteOptions(request, run, json);
  WriteMasks(request, run, json);
  WriteColourCalibration(request, run, json);
  WriteStatistics(request, run, json);
  WriteLevels(request, run, json);
  WriteOutputs(request, run, json);
  WriteMesh(request, run, json);
  json.EndObject();
  return json.str();
}

}  // namespace raycarve
