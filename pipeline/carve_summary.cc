// The summary `raycarve carve` prints at its end (and report.html shows): what was carved, from
// what, what was written, and what to do next.
#include "pipeline/carve_summary.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>

#include "pipeline/carve_report.h"

namespace raycarve {
namespace {

// printf into the end of *text.
__attribute__((format(printf, 2, 3))) void Appendf(std::string* text, const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  if (n > 0) {
    const size_t at = text->size();
    text->resize(at + static_cast<size_t>(n) + 1);
    std::vsnprintf(text->data() + at, static_cast<size_t>(n) + 1, format, args);
    text->resize(at + static_cast<size_t>(n));
  }
  va_end(args);
}

// A share of the surface on the box's walls from which the summary says what would help: a
// tenth of the model is a cut that a user sees at once.
constexpr double kGuidanceWallShare = 0.1;

// One line on where the masks came from: per source the count, and for backdrop masks the
// colours found (those of the first such photo), frames and the median object share.
std::string MaskSummary(const std::vector<PhotoMaskInfo>& photos) {
  std::map<std::string, int> count;
  std::vector<double> shares;
  const PhotoMaskInfo* first_backdrop = nullptr;
  int framed = 0, no_backdrop = 0;
  for (const PhotoMaskInfo& photo : photos) {
    ++count[photo.source];
    if (photo.source != "none") shares.push_back(photo.object_share);
    if (photo.source == "backdrop") {
      if (first_backdrop == nullptr) first_backdrop = &photo;
      framed += std::max({photo.backdrop.frame[0], photo.backdrop.frame[1],
                          photo.backdrop.frame[2], photo.backdrop.frame[3]}) > 0;
    }
    no_backdrop += photo.source == "none" && photo.backdrop.explained > 0.0;
  }
  std::ostringstream text;
  const char* separator = "";
  for (const auto& [source, n] : count) {
    text << separator << n << (source == "file"       ? " from mask files"
                               : source == "backdrop" ? " from the backdrop"
                               : source == "colour"   ? " from the given backdrop colour"
                                                      : " without a mask");
    separator = ", ";
  }
  if (first_backdrop != nullptr) {
    text << "; backdrop of the first: " << first_backdrop->backdrop.Summary();
    if (framed > 0) text << "; " << framed << " photos with a frame";
  }
  if (no_backdrop > 0) text << "; " << no_backdrop << " photos show no plain backdrop (natural scene?)";
  if (!shares.empty()) {
    std::nth_element(shares.begin(), shares.begin() + shares.size() / 2, shares.end());
    text << "; object " << std::lround(100.0 * shares[shares.size() / 2])
         << "% of a photo (median)";
  }
  return text.str();
}

// The summary printed at the end: what was carved, from what, and what was written.
// What the mesh is: closed, or open only where the box's walls were left out, or neither.
std::string MeshShape(const CarveRun& run) {
  const exporter::MeshTopology& t = run.mesh_topology;
  if (t.IsClosedManifold()) return "closed and 2-manifold";
  if (run.mesh_wall_triangles_removed > 0 && t.non_manifold_edges == 0 &&
      t.self_intersecting_pairs == 0) {
    // Where two removed stretches of wall meet at a corner, two sheets of surface touch at a
    // vertex: said, not hidden.
    const bool framed_out = run.mesh_uncovered_triangles_removed > 0;
    const bool behind = run.mesh_unseen_triangles_removed > 0;
    return std::string("open where the box cuts the scene") +
           (framed_out && behind ? ", beyond the photos' frames and behind the subjects"
            : framed_out         ? " and beyond the photos' frames"
            : behind             ? " and behind the subjects"
                                 : "") +
           (t.non_manifold_vertices > 0
                ? " (" + std::to_string(t.non_manifold_vertices) +
                      (t.non_manifold_vertices == 1 ? " vertex" : " vertices") +
                      " where two sheets touch)"
                : std::string());
  }
  return "NOT a closed 2-manifold: " + t.Faults();
}

// After the grid line: how many pixels of the photos a voxel spans, and, where under one, what
// the photos support.
std::string ResolutionText(const CarveRun& run) {
  if (!(run.voxel_pixels > 0.0)) return "";
  char text[320];
  if (run.resolution_lowered_from > 0) {
    std::snprintf(text, sizeof(text),
                  ", a voxel spans %.2f px of the photos\n"
                  "  resolution      the default %d lowered to %d: the photos resolve no finer "
                  "(--resolution chooses)",
                  run.voxel_pixels, run.resolution_lowered_from, run.supported_resolution);
  } else if (run.hull_resolution_from > 0) {
    std::snprintf(text, sizeof(text),
                  ", a voxel spans %.2f px of the photos\n"
                  "  resolution      the default %d lowered to %d in the box narrowed to the "
                  "masks: finer voxels scored worse (--resolution chooses)",
                  run.voxel_pixels, run.hull_resolution_from, run.hull_resolution);
  } else if (run.voxel_pixels >= 1.0) {
    std::snprintf(text, sizeof(text), ", a voxel spans %.2f px of the photos", run.voxel_pixels);
  } else {
    std::snprintf(text, sizeof(text),
                  ", a voxel spans %.2f px of the photos\n"
                  "  resolution      finer than the photos resolve: they support about "
                  "--resolution %d (a voxel of one pixel); larger photos (--max_image_size) or "
                  "nearer cameras support more",
                  run.voxel_pixels, run.supported_resolution);
  }
  return text;
}

// The summary's capture entry: how the cameras stand, the volume chosen, the supporting plane
// and the ground held under it, a line each.
std::string CaptureText(const CarveRun& run) {
  const std::string next_line = "\n                  ";
  std::string text = run.layout.Summary();
  if (run.bounds.around_focus) text += next_line + "the volume: the box around their focus";
  if (run.bounds.around_hull) {
    text += next_line + "the volume: the box around what the masks call the object (where the "
            "sparse points are)";
  }
  if (run.bounds.depth_tried_points > 0) {
    text += next_line + "the volume: the " + std::to_string(run.bounds.depth_resolved_points) +
            " of " + std::to_string(run.bounds.depth_tried_points) +
            " sparse points the photos place in depth to two voxels (the rest too far for the "
            "cameras' baseline)";
  }
  if (run.distant_reason.empty()) {
    const DistantPixels& d = run.distant;
    char line[320];
    std::snprintf(line, sizeof(line),
                  "distant: %.1f%% of the photos' textured pixels move as things beyond the "
                  "volume do (sky, far hills), with %lld pixels of plain regions they bound; "
                  "their rays carved %lld voxels",
                  d.textured > 0 ? 100.0 * d.distant / d.textured : 0.0,
                  static_cast<long long>(d.grown),
                  static_cast<long long>(run.result->statistics.distant_carved));
    text += next_line + line;
  }
  text += next_line + run.plane.Summary();
  if (run.plane.found) {
    text += next_line + "ground: " + run.ground_reason;
    if (!run.ground.empty()) {
      const CarveStatistics& s = run.result->statistics;
      text += " (" + std::to_string(s.ground_voxels) + " voxels; " +
              std::to_string(s.beyond_ground_carved) + " below it past its edge carved)";
      if (run.ground_pixels_reason.empty()) {
        const DistantPixels& g = run.ground_pixels;
        char line[240];
        std::snprintf(line, sizeof(line),
                      "ground seen: %.1f%% of the photos' textured pixels move as the ground does "
                      "(%lld found above it); their rays carved %lld voxels above it",
                      g.textured > 0 ? 100.0 * g.distant / g.textured : 0.0,
                      static_cast<long long>(g.nearer), static_cast<long long>(s.ground_seen_carved));
        text += next_line + line;
      }
    }
  }
  return text;
}


// The summary's line on the sparse points in the volume.
std::string SparseLine(const CarveRequest& request, const CarveRun& run) {
  if (!run.has_sparse) return "none in the volume";
  char text[240];
  std::snprintf(text, sizeof(text), "%zu in the volume: %.1f%% within 2 voxels of the cloud, 90%% within %.2f voxels%s",
                run.sparse.num_reconstruction, 100.0 * run.sparse.precision,
                run.sparse.accuracy / run.result->statistics.voxel_size,
                request.options.protect_surface_points
                    ? "\n                  (known surface keeps the reliable ones' voxels: no independent measure)"
                    : "");
  return text;
}

// The lines on the tiles joined and the silhouettes repaired, where there were any.
std::string TilesAndSilhouettesLines(const CarveRun& run) {
  const CarveStatistics& s = run.result->statistics;
  std::string silhouette_line;
  if (s.silhouette_repair.views > 0) {
    silhouette_line = "  silhouettes     " + std::to_string(s.silhouette_repair.lost_pixels) +
                      " object pixels of the masks had lost the model to carving; " +
                      std::to_string(s.silhouette_repair.restored_voxels) + " voxels restored\n";
  }
  if (run.tiled.jobs > 0) {
    char tiles[240];
    std::snprintf(tiles, sizeof(tiles),
                  "  tiles           joined from %d jobs of plan %s (%dx%dx%d tiles, overlap %d "
                  "voxels), carved on with the whole volume's visibility: %lld evaluations\n",
                  run.tiled.jobs, run.tiled.plan_id.c_str(), run.tiled.tiles_per_axis.x(),
                  run.tiled.tiles_per_axis.y(), run.tiled.tiles_per_axis.z(), run.tiled.overlap,
                  static_cast<long long>(s.evaluated));
    silhouette_line = tiles + silhouette_line;
  }
  return silhouette_line;
}

// The levels of detail: each one's resolution and threshold.
std::string LevelsText(const CarveRequest& request, const CarveStatistics& s) {
  std::string level_line;
  for (const LevelStatistics& level : s.levels) {
    char text[96];
    if (request.options.consistency == ConsistencyMethod::kPatchCorrelation) {
      std::snprintf(text, sizeof(text), "%s%d voxels at threshold %.3g, pattern %.2f",
                    level_line.empty() ? "" : "; ", level.resolution, level.threshold,
                    level.pattern_threshold);
    } else {
      std::snprintf(text, sizeof(text), "%s%d voxels at threshold %.3g",
                    level_line.empty() ? "" : ", ", level.resolution, level.threshold);
    }
    level_line += text;
    if (level.image_enlargement > 1) {
      level_line += " (photos enlarged " + std::to_string(level.image_enlargement) + "x)";
    }
  }
  return level_line;
}

void AppendSummary(const CarveRequest& request, const CarveRun& run, std::string* text) {
  const CarveStatistics& s = run.result->statistics;
  const std::string sparse_line = SparseLine(request, run);
  const std::string mask_line =
      run.backdrop_masks_dropped > 0
          ? "a backdrop found in " + std::to_string(run.backdrop_masks_dropped) + " of " +
                std::to_string(run.mask_photos.size()) +
                " photos only (a minority): not the capture's, every photo used whole"
          : MaskSummary(run.mask_photos);
  const std::string silhouette_line = TilesAndSilhouettesLines(run);
  size_t judged_voxels = 0;
  for (const ColouredVoxel& voxel : run.result->surface) {
    judged_voxels += voxel.num_views >= request.options.min_views;
  }
  std::string level_line = LevelsText(request, s);
  if (run.spread_floor > 0.0) {
    char floor[64];
    std::snprintf(floor, sizeof(floor), "; at least %.3g x a voxel's within-view spread",
                  run.spread_floor);
    level_line += floor;
  }
  if (!s.levels.empty() && s.levels.front().first_pass_seconds > 0.0) {
    char seen[160];
    const ThresholdEstimate& final_estimate = s.levels.back().estimate;
    std::snprintf(seen, sizeof(seen),
                  "; measured on the %.3g photos a sparse point that see it, not its track's %.2g",
                  final_estimate.ViewsPerPoint(), final_estimate.TrackViewsPerPoint());
    level_line += seen;
  }
  std::string floater_text;
  if (s.unsupported_components > 0) {
    floater_text = ", " + std::to_string(s.unsupported_component_carved) + " in " +
                   std::to_string(s.unsupported_components) + " floaters without sparse points";
  }
  Appendf(text, 
      "\ncarved %s\n"
      "  grid            %d x %d x %d voxels of %.4g (%lld voxels)%s\n"
      "  carved          %lld voxels (%lld by the visual hull of %d masked views, %lld by the "
      "sparse points' sight lines, %lld in specks%s), %lld evaluations\n"
      "  levels          %zu (%s)\n"
      "  convergence     %.2f s (+ %.2f s set-up) on %s, carving structures' peak %.1f MiB\n"
      "  process memory  %.1f MiB at its peak (resident: photos, views, grid, mesh)\n"
      "  surface         %lld voxels, %lld seen by the photos, %zu by %d or more\n"
      "  sparse points   %s\n"
      "  capture         %s\n"
      "  masks           %s\n"
      "%s"
      "  outputs         %s/cloud.ply (%zu points, seen by %d+ photos), mesh.ply (%zu triangles),\n"
      "                  %sreport.json, convergence.csv\n"
      "  look            %s/report.html in a browser (the model in 3D, the figures, pictures);\n"
      "                  mesh.ply in MeshLab, CloudCompare, Open3D or colmap gui\n",
      run.model_path.c_str(), s.dimensions.x(), s.dimensions.y(), s.dimensions.z(), s.voxel_size,
      static_cast<long long>(s.num_voxels), ResolutionText(run).c_str(),
      static_cast<long long>(s.carved),
      static_cast<long long>(s.visual_hull_carved), s.views_with_masks,
      static_cast<long long>(s.free_space_level0_carved),
      static_cast<long long>(s.component_carved), floater_text.c_str(),
      static_cast<long long>(s.evaluated),
      s.levels.size(), level_line.c_str(), s.carve_seconds, s.setup_seconds,
      s.ThreadsText().c_str(), s.peak_memory_bytes / (1024.0 * 1024.0), ProcessPeakMiB(), static_cast<long long>(s.final_surface),
      static_cast<long long>(s.visible_surface), judged_voxels, request.options.min_views,
      sparse_line.c_str(),
      CaptureText(run).c_str(),
      mask_line.c_str(),
      silhouette_line.c_str(), run.output_path.c_str(),
      run.num_cloud_points,
      request.mesh_kind == "smooth" ? request.cloud_min_views : request.options.min_views,
      run.num_mesh_triangles,
      request.mesh_kind != "smooth" ? ""
      : run.mesh_texture.atlas_width > 0
          ? "mesh.glb, mesh.obj (+ mesh.mtl, mesh_texture.png: textured from the photos),\n                  preview.png, "
          : "mesh.glb, preview.png, ",
      run.output_path.c_str());
}

// What to do next when the capture has no masks and the box cuts much of its surroundings: the
// box around what the cameras look at, and masks.
void AppendGuidance(const CarveRequest& request, const CarveRun& run, std::string* text) {
  const bool masked = run.masks_from_files + run.masks_from_backdrop > 0;
  if (masked || run.bounds.is_explicit || run.WallShare() < kGuidanceWallShare) return;
  if (run.layout.object_centred) {
    Appendf(text, "  next            the volume's box cuts the surroundings around the subject (%.0f%% "
                "of the surface lay on its walls):\n",
                100.0 * run.WallShare());
  } else if (run.bounds.depth_tried_points > 0) {
    Appendf(text, "  next            a scene: the box holds the %d of %d sparse points the photos place "
                "in depth (the rest: --capture scene, at coarser voxels and a depth they cannot "
                "place), and cuts what runs on beyond them (%.0f%% of the surface lay on its "
                "walls). To carve one subject alone:\n",
                run.bounds.depth_resolved_points, run.bounds.depth_tried_points,
                100.0 * run.WallShare());
  } else {
    Appendf(text, "  next            a scene: the box holds the sparse points several photos share, and "
                "cuts what runs on beyond them (%.0f%% of the surface lay on its walls). To carve "
                "one subject alone:\n",
                100.0 * run.WallShare());
  }
  const Eigen::AlignedBox3d& focus = run.layout.focus_box;
  const bool box_hint = run.layout.object_centred && !focus.isEmpty() && !run.bounds.around_focus;
  if (box_hint) {
    const std::string project = request.workspace_path.empty()
                                    ? "--input_path " + run.model_path + " --image_path " +
                                          run.image_path
                                    : "--workspace_path " + request.workspace_path;
    Appendf(text, "                  to carve what the cameras look at (%d sparse points framed "
                "around their common focus):\n"
                "                  raycarve carve %s --bbox %.4g,%.4g,%.4g,%.4g,%.4g,%.4g\n",
                run.layout.focus_box_points, project.c_str(), focus.min().x(), focus.min().y(),
                focus.min().z(), focus.max().x(), focus.max().y(), focus.max().z());
  }
  Appendf(text, "                  %s the subject's masks (--mask_path, one <photo>.png per photo, "
              "white on the subject): the carve then keeps the subject alone\n",
              box_hint ? "or give" : "give");
}

// Warnings, COLMAP's mesher line and the mesh's figures, after the summary.
void AppendAfterSummary(const CarveRequest& request, const CarveRun& run, std::string* text) {
  const CarveStatistics& s = run.result->statistics;
  if (s.final_solid == 0 || s.visible_surface == 0) {
    Appendf(text, 
        "  warning         the carve kept nothing %s: the files are valid but empty. Try a higher "
        "--threshold (or auto), --protect_surface_points 1, and check that the photos see the "
        "volume (--bbox, the masks in %s/masks)\n",
        s.final_solid == 0 ? "(every voxel was found inconsistent or unseen)"
                           : "that a photo sees",
        run.output_path.c_str());
  }
  if (request.mesh_kind == "smooth" && run.num_cloud_points > 0) {
    // COLMAP's Poisson trim of 10 suits its own fused clouds of megapixel photos; a cloud of one
    // point per pixel of smaller photos is thinner, and trim 10 leaves nothing (measured on the
    // demo: densities 3.9-9.3, 0 vertices at trim 10, 556k at 5).
    Appendf(text, "  COLMAP mesher   colmap poisson_mesher --input_path %s/fused.ply --output_path "
                "%s/poisson.ply --PoissonMeshing.trim 5\n",
                run.output_path.c_str(), run.output_path.c_str());
    if (run.dense_sparse_skipped.empty()) {
      Appendf(text, "                  (the output is a COLMAP dense workspace: fused.ply, fused.ply.vis, "
                  "sparse/; colmap delaunay_mesher --input_path %s --input_type dense, where "
                  "COLMAP has CGAL)\n",
                  run.output_path.c_str());
    } else {
      Appendf(text, "                  (sparse/ not written: %s)\n", run.dense_sparse_skipped.c_str());
    }
  }
  if (request.mesh_kind == "smooth" && run.num_mesh_triangles > 0) {
    const exporter::MeshColouringSummary& c = run.mesh_colouring;
    Appendf(text, "  mesh            %zu triangles, %zu vertices, %lld component%s, %s;\n"
                "                  %.1f%% of its vertices coloured from %d+ photos (%.1f each), "
                "the rest from seen neighbours\n",
                run.num_mesh_triangles, run.num_mesh_vertices,
                static_cast<long long>(run.mesh_topology.components),
                run.mesh_topology.components == 1 ? "" : "s",
                MeshShape(run).c_str(), 100.0 * c.SeenShare(), request.mesh.min_views,
                c.mean_views);
    if (run.mesh_wall_triangles_removed > 0) {
      Appendf(text, "                  %.1f%% of the surface lay on the volume box's walls, where the "
                  "box cuts the scene: left out of the mesh and the cloud\n",
                  100.0 * run.WallShare());
      if (run.mesh_uncovered_triangles_removed > 0) {
        Appendf(text, "                  %lld triangles beyond the frames of all but one photo "
                    "(never judged, kept solid by the carve): left out of the mesh\n",
                    static_cast<long long>(run.mesh_uncovered_triangles_removed));
      }
      if (run.mesh_unseen_triangles_removed > 0) {
        Appendf(text, "                  %lld triangles fewer than two photos see, behind the subjects "
                    "from every camera (never judged, kept solid by the carve): left out of the mesh "
                    "(%lld vertices within a voxel of what they see kept, closing the subjects' rims)\n",
                    static_cast<long long>(run.mesh_unseen_triangles_removed),
                    static_cast<long long>(run.mesh_unseen_vertices_kept));
      }
    } else if (run.mesh_grid_wall_vertices > 0) {
      Appendf(text, "                  %lld vertices on the volume box's walls, where the box cuts the "
                  "scene: in the mesh, left out of the cloud\n",
                  static_cast<long long>(run.mesh_grid_wall_vertices));
    }
  }
  AppendGuidance(request, run, text);
}

}  // namespace

std::string CarveSummaryText(const CarveRequest& request, const CarveRun& run) {
  std::string text;
  AppendSummary(request, run, &text);
  AppendAfterSummary(request, run, &text);
  return text;
}

}  // namespace raycarve
