#include "export/carve_export.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include <glog/logging.h>

#include <pcl/PolygonMesh.h>
#include <pcl/conversions.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "calib/atomic_file.h"
#include "calib/input_error.h"
#include "carve/view_workers.h"
#include "export/mesh_renderer.h"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the point visibility file is written little-endian by memcpy");

namespace raycarve {
namespace exporter {
namespace {

bool Solid(const Volume& volume, const Eigen::Vector3i& voxel) { return volume.IsSolid(voxel); }

}  // namespace

std::vector<ColouredPoint> SurfacePoints(const CarveResult& result, int min_views) {
  const Volume& volume = result.volume;
  const VoxelGrid& grid = volume.grid();
  std::vector<ColouredPoint> points;
  for (const ColouredVoxel& coloured : result.surface) {
    if (coloured.num_pixels == 0 || coloured.num_views < min_views) continue;
    const Eigen::Vector3i voxel = grid.Voxel(coloured.index);
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3i offset(dx, dy, dz);
          if (offset == Eigen::Vector3i::Zero() || Solid(volume, voxel + offset)) continue;
          normal += offset.cast<double>().normalized();
        }
      }
    }
    ColouredPoint point;
    point.xyz = grid.Centre(voxel).cast<float>();
    if (normal.norm() > 1e-9) point.normal = normal.normalized().cast<float>();
    point.rgb = ToRgb(coloured.colour);
    points.push_back(point);
  }
  return points;
}

MeshSummary WriteVoxelMeshPly(const CarveResult& result, const std::string& path) {
  const Volume& volume = result.volume;
  const VoxelGrid& grid = volume.grid();
  pcl::PointCloud<pcl::PointXYZRGB> vertices;
  pcl::PolygonMesh mesh;
  // The 6 faces: axis, side, and the 4 corner bits (x, y, z) of the face in counter-clockwise
  // order seen from outside.
  struct Face {
    Eigen::Vector3i normal;
    int corners[4];
  };
  const Face faces[6] = {{{1, 0, 0}, {1, 3, 7, 5}},  {{-1, 0, 0}, {0, 4, 6, 2}},
                         {{0, 1, 0}, {2, 6, 7, 3}},  {{0, -1, 0}, {0, 1, 5, 4}},
                         {{0, 0, 1}, {4, 5, 7, 6}},  {{0, 0, -1}, {0, 2, 3, 1}}};
  for (const ColouredVoxel& coloured : result.surface) {
    const Eigen::Vector3i voxel = grid.Voxel(coloured.index);
    const Eigen::Matrix<uint8_t, 3, 1> rgb =
        coloured.num_pixels > 0 ? ToRgb(coloured.colour) : Eigen::Matrix<uint8_t, 3, 1>(128, 128, 128);
    for (const Face& face : faces) {
      if (Solid(volume, voxel + face.normal)) continue;
      const auto first = static_cast<pcl::index_t>(vertices.size());
      for (int corner : face.corners) {
        const Eigen::Vector3d p = grid.Corner(voxel, corner);
        pcl::PointXYZRGB vertex;
        vertex.x = static_cast<float>(p.x());
        vertex.y = static_cast<float>(p.y());
        vertex.z = static_cast<float>(p.z());
        vertex.r = rgb[0];
        vertex.g = rgb[1];
        vertex.b = rgb[2];
        vertices.push_back(vertex);
      }
      pcl::Vertices triangle;
      triangle.vertices = {first, first + 1, first + 2};
      mesh.polygons.push_back(triangle);
      triangle.vertices = {first, first + 2, first + 3};
      mesh.polygons.push_back(triangle);
    }
  }
  vertices.width = static_cast<uint32_t>(vertices.size());
  vertices.height = 1;
  pcl::toPCLPointCloud2(vertices, mesh.cloud);
  const std::string temporary = TemporaryPathFor(path);
  if (pcl::io::savePLYFileBinary(temporary, mesh) != 0) {
    throw InputError(temporary + ": PCL could not write the mesh");
  }
  RenameIntoPlace(temporary, path);
  return {vertices.size(), mesh.polygons.size()};
}

bool ModelMeshOptions::IsValid(std::string* reason) const {
  if (!(edge_pixels >= 0.0) || !std::isfinite(edge_pixels)) {
    *reason = "mesh edge length in pixels must be >= 0";
    return false;
  }
  // The geometry's own options say what is wrong with the smoothing and the face budget.
  SurfaceMeshOptions geometry;
  geometry.smoothing_iterations = smoothing_iterations;
  geometry.max_triangles = max_triangles;
  if (!geometry.IsValid(reason)) return false;
  if (min_views < 1) {
    *reason = "mesh colouring needs min_views >= 1";
    return false;
  }
  if (min_component_vertices < 0) {
    *reason = "mesh minimum component size must be >= 0";
    return false;
  }
  if (final_smoothing_iterations < 0) {
    *reason = "mesh final smoothing iterations must be >= 0";
    return false;
  }
  if (refine_passes < 0) {
    *reason = "mesh refinement passes must be >= 0";
    return false;
  }
  if (part_min_views < 0) {
    *reason = "mesh part minimum views must be >= 0";
    return false;
  }
  if (silhouette_passes < 0) {
    *reason = "mesh silhouette passes must be >= 0";
    return false;
  }
  if (!(refine_converged_voxels >= 0.0) || !std::isfinite(refine_converged_voxels)) {
    *reason = "mesh refinement convergence (voxels) must be a number >= 0";
    return false;
  }
  if (!(refine_search_pixels >= 0.0) || !std::isfinite(refine_search_pixels)) {
    *reason = "mesh refinement search (pixels) must be a number >= 0";
    return false;
  }
  return true;
}

void RemoveGridWalls(ModelMesh* model, const std::vector<Eigen::Vector3d>& anchors,
                     double anchor_radius) {
  TriangleMesh& mesh = model->mesh;
  CHECK(model->on_grid_wall.size() == mesh.vertices.size());
  model->triangles_before_walls = static_cast<int64_t>(mesh.triangles.size());
  std::vector<Eigen::Vector3i> kept;
  kept.reserve(mesh.triangles.size());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    if (model->on_grid_wall[t[0]] && model->on_grid_wall[t[1]] && model->on_grid_wall[t[2]]) {
      ++model->wall_triangles_removed;
    } else {
      kept.push_back(t);
    }
  }
  if (model->wall_triangles_removed == 0) return;
  mesh.triangles = std::move(kept);
  // Slivers that only the wall held to the rest: specks now (SpeckVertices), left out too.
  const std::vector<uint8_t> speck = SpeckVertices(mesh, anchors, anchor_radius);
  kept.clear();
  for (const Eigen::Vector3i& t : mesh.triangles) {
    if (speck[t[0]]) {
      ++model->wall_sliver_triangles_removed;
    } else {
      kept.push_back(t);
    }
  }
  mesh.triangles = std::move(kept);
  // The vertices still used, renumbered in order, with everything kept per vertex.
  std::vector<int> new_index(mesh.vertices.size(), -1);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int j = 0; j < 3; ++j) new_index[t[j]] = 0;
  }
  int next = 0;
  for (int& index : new_index) {
    if (index == 0) index = next++;
  }
  const auto compact = [&](auto* values) {
    if (values->size() != new_index.size()) return;
    for (size_t i = 0; i < new_index.size(); ++i) {
      if (new_index[i] >= 0) (*values)[new_index[i]] = std::move((*values)[i]);
    }
    values->resize(next);
  };
  compact(&mesh.vertices);
  compact(&mesh.normals);
  compact(&mesh.colours);
  compact(&model->seen_by);
  compact(&model->on_grid_wall);
  compact(&model->refinement.pinned);
  for (Eigen::Vector3i& t : mesh.triangles) {
    for (int j = 0; j < 3; ++j) t[j] = new_index[t[j]];
  }
}

std::string FinalSmoothingSummary(const ModelMesh& model, const ModelMeshOptions& options) {
  if (options.final_smoothing_iterations == 0 || model.refinement.passes == 0) {
    return "mesh final smoothing: none";
  }
  char text[200];
  std::snprintf(text, sizeof(text),
                "mesh final smoothing: %d passes, applied by the share the photos leave open "
                "(mean %.0f%%); vertices moved %.3g on average",
                options.final_smoothing_iterations, 100.0 * (1.0 - model.refinement.mean_pinned),
                model.final_smoothing_mean_move);
  return text;
}

namespace {

void Tell(const ModelMeshOptions& options, const std::string& line) {
  if (options.progress) options.progress(line);
}

// The iso-surface's positions (`iso_surface`, one per vertex of `meshed`, the mesh as
// MeshSolidVoxels made it) of the vertices `mesh` keeps after removals, found by the smoothed
// position (which the removals copy bit for bit); `mesh`'s own positions where any is not found.
std::vector<Eigen::Vector3f> IsoSurfaceOf(const std::vector<Eigen::Vector3f>& iso_surface,
                                          const std::vector<Eigen::Vector3f>& meshed,
                                          const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3f> unrefined = mesh.vertices;
  if (iso_surface.size() != meshed.size() || iso_surface.empty()) return unrefined;
  // Sorted by position, then index: of equal positions the first vertex answers. (A sorted array,
  // not a tree: at 1024 voxels, six million vertices.)
  using Key = std::pair<std::array<float, 3>, int>;
  std::vector<Key> at(meshed.size());
  for (size_t v = 0; v < meshed.size(); ++v) {
    at[v] = {{meshed[v].x(), meshed[v].y(), meshed[v].z()}, static_cast<int>(v)};
  }
  std::sort(at.begin(), at.end());
  for (Eigen::Vector3f& p : unrefined) {
    const std::array<float, 3> position{p.x(), p.y(), p.z()};
    const auto found = std::lower_bound(at.begin(), at.end(), Key{position, -1});
    if (found == at.end() || found->first != position) return mesh.vertices;
    p = iso_surface[found->second];
  }
  return unrefined;
}

// Refinement from the photos, then the final smoothing where the photos leave the position open.
void RefineModel(const std::vector<CalibratedView>& views, const VoxelGrid& grid,
                 const ModelMeshOptions& options, double smoothing_pass_band, ModelMesh* model) {
  MeshRefinementOptions refinement;
  refinement.passes = options.refine_passes;
  refinement.converged_offset = options.refine_converged_voxels * grid.voxel_size();
  // A voxel either side; on a grid finer than the photos, the pixels asked where further.
  const double pixel = MedianPixelFootprint(views, grid.Box().center());
  refinement.search_range = grid.voxel_size() < pixel
                                ? std::max(grid.voxel_size(), options.refine_search_pixels * pixel)
                                : grid.voxel_size();
  refinement.patch_radius = 0.5 * grid.voxel_size();
  refinement.depth_tolerance = grid.voxel_size();
  refinement.voxel_size = grid.voxel_size();
  refinement.min_views = std::max(2, options.min_views);
  refinement.num_threads = options.num_threads;
  if (refinement.passes == 0) return;
  char reach[64];
  std::snprintf(reach, sizeof(reach), "%.2f", refinement.search_range / grid.voxel_size());
  Tell(options, "mesh refinement: at most " + std::to_string(refinement.passes) + " passes over " +
                    std::to_string(model->mesh.vertices.size()) + " vertices, from " +
                    std::to_string(views.size()) + " photos, searching +-" + reach +
                    " voxels ...");
  model->refinement = RefineMeshFromPhotos(views, refinement, &model->mesh);
  Tell(options, model->refinement.Summary());
  if (options.final_smoothing_iterations == 0) return;
  // Smoothed where the photos leave the position open, kept where they pin it.
  TriangleMesh smooth = model->mesh;
  SmoothMesh(options.final_smoothing_iterations, smoothing_pass_band, &smooth);
  double moved = 0.0;
  for (size_t i = 0; i < model->mesh.vertices.size(); ++i) {
    const float open = 1.0f - model->refinement.pinned[i];
    const Eigen::Vector3f step = open * (smooth.vertices[i] - model->mesh.vertices[i]);
    model->mesh.vertices[i] += step;
    moved += step.norm();
  }
  model->final_smoothing_mean_move = moved / static_cast<double>(model->mesh.vertices.size());
  ComputeVertexNormals(&model->mesh);
  Tell(options, FinalSmoothingSummary(*model, options));
}

// The walls are found on the final geometry and left out before colouring, so that the colour
// figures describe the mesh written.
void MarkAndRemoveWalls(const VoxelGrid& grid, const std::vector<CalibratedView>& views,
                        const ModelMeshOptions& options, ModelMesh* model) {
  model->on_grid_wall = GridWallVertices(model->mesh, grid);
  model->grid_wall_vertices =
      std::count(model->on_grid_wall.begin(), model->on_grid_wall.end(), uint8_t{1});
  if (!options.remove_grid_walls) return;
  const std::vector<uint8_t> fill =
      GroundFillVertices(model->mesh, options.ground, grid.voxel_size());
  const std::vector<uint8_t> uncovered = UncoveredVertices(model->mesh, views, options.min_views);
  std::vector<uint8_t> unseen =
      options.remove_unseen
          ? UnseenVertices(model->mesh, views, options.min_views, grid.voxel_size())
          : std::vector<uint8_t>(model->mesh.vertices.size(), 0);
  const auto all = [](const std::vector<uint8_t>& marks, const Eigen::Vector3i& t) {
    return marks[t[0]] && marks[t[1]] && marks[t[2]];
  };
  std::vector<uint8_t> wall_or_fill = model->on_grid_wall, framed_out, any;
  for (size_t i = 0; i < fill.size(); ++i) wall_or_fill[i] |= fill[i];
  framed_out = wall_or_fill;
  for (size_t i = 0; i < fill.size(); ++i) framed_out[i] |= uncovered[i];
  if (options.remove_unseen) {
    model->unseen_vertices_kept = KeepUnseenNearSeen(model->mesh, framed_out, grid.voxel_size(), &unseen);
  }
  any = framed_out;
  for (size_t i = 0; i < fill.size(); ++i) any[i] |= unseen[i];
  for (const Eigen::Vector3i& t : model->mesh.triangles) {
    const bool on_wall = all(model->on_grid_wall, t);
    model->ground_fill_triangles_removed += !on_wall && all(fill, t);
    model->uncovered_triangles_removed += !all(wall_or_fill, t) && all(framed_out, t);
    model->unseen_triangles_removed += !all(framed_out, t) && all(any, t);
  }
  model->on_grid_wall = std::move(any);
  RemoveGridWalls(model, options.sparse_points, 1.5 * grid.voxel_size());
  if (model->wall_sliver_triangles_removed > 0 || model->ground_fill_triangles_removed > 0 ||
      model->uncovered_triangles_removed > 0 || model->unseen_triangles_removed > 0) {
    Tell(options, "mesh walls: " + std::to_string(model->wall_triangles_removed) +
                      " triangles on the volume box's walls left out (" +
                      std::to_string(model->ground_fill_triangles_removed) +
                      " more of the held ground's sides and underside, " +
                      std::to_string(model->uncovered_triangles_removed) +
                      " beyond the frames of all but " + std::to_string(options.min_views - 1) +
                      " photo, " + std::to_string(model->unseen_triangles_removed) +
                      " seen by fewer than " + std::to_string(options.min_views) +
                      " photos, those within a voxel of what they see kept: " +
                      std::to_string(model->unseen_vertices_kept) + " vertices), then " +
                      std::to_string(model->wall_sliver_triangles_removed) +
                      " triangles of slivers only the walls held to the model (no sparse point "
                      "on them)");
  }
}

// Vertex colours from the photos, then the texture atlas.
void ColourModel(const std::vector<CalibratedView>& views, const VoxelGrid& grid,
                 const ModelMeshOptions& options, ModelMesh* model) {
  MeshColouringOptions colouring;
  colouring.min_views = options.min_views;
  colouring.depth_tolerance = grid.voxel_size();
  colouring.num_threads = options.num_threads;
  model->colouring = ColourMeshFromPhotos(views, colouring, &model->mesh, &model->seen_by);
  Tell(options, model->colouring.Summary());
  if (options.texture && !model->mesh.empty()) {
    MeshTextureOptions texture = options.texture_options;
    texture.num_threads = options.num_threads;
    model->texture = TextureMeshFromPhotos(views, model->seen_by, texture, &model->mesh);
    Tell(options, model->texture.Summary());
  }
}

}  // namespace

ModelMesh MeshCarvedModel(const CarveResult& result,
                          const std::vector<CalibratedView>& views,
                          const ModelMeshOptions& options) {
  std::string reason;
  CHECK(options.IsValid(&reason)) << reason;
  const VoxelGrid& grid = result.volume.grid();
  SurfaceMeshOptions geometry;
  geometry.smoothing_iterations = options.smoothing_iterations;
  geometry.max_triangles = options.max_triangles;
  if (options.edge_pixels > 0.0) {
    const double pixel = MedianPixelFootprint(views, grid.Box().center());
    geometry.max_edge_length = std::max(0.25 * grid.voxel_size(), options.edge_pixels * pixel);
  }
  ModelMesh model;
  std::vector<Eigen::Vector3f> iso_surface;
  model.mesh = MeshSolidVoxels(result.volume, geometry, &model.geometry, &iso_surface);
  const std::vector<Eigen::Vector3f> meshed = model.mesh.vertices;
  model.small_components_removed =
      RemoveSmallComponents(options.min_component_vertices, &model.mesh);
  Tell(options, model.geometry.Summary());
  model.parts = RemoveUnneededParts(views, options.part_min_views, options.sparse_points,
                                    1.5 * grid.voxel_size(), options.num_threads, &model.mesh);
  if (model.parts.removed > 0 || model.parts.anchored > 0) Tell(options, model.parts.Summary());
  if (model.mesh.empty()) return model;
  // What UndoSelfIntersections returns vertices towards: the iso-surface before smoothing, which
  // never folds through itself; else (splitting or decimation) the smoothed one.
  const std::vector<Eigen::Vector3f> unrefined = IsoSurfaceOf(iso_surface, meshed, model.mesh);
  RefineModel(views, grid, options, geometry.smoothing_pass_band, &model);
  if (options.silhouette_passes > 0) {
    SilhouetteFitOptions fit;
    fit.passes = options.silhouette_passes;
    fit.max_move = grid.voxel_size();
    fit.depth_tolerance = grid.voxel_size();
    fit.num_threads = options.num_threads;
    model.silhouettes = FitMeshToSilhouettes(views, fit, &model.mesh);
    if (model.silhouettes.passes > 0) Tell(options, model.silhouettes.Summary());
  }
  const int threads = options.num_threads > 0 ? options.num_threads : ResolveNumThreads(-1);
  UndoOptions undo;
  undo.num_threads = threads;
  undo.progress = [&options](const std::string& line) {
    Tell(options, "mesh self-intersections: " + line);
  };
  if (options.undo_self_intersections) {
    model.self_intersections = UndoSelfIntersections(unrefined, &model.mesh, undo);
    Tell(options, "mesh self-intersections: " + model.self_intersections.Summary());
  }
  if (!options.support.empty()) {
    const std::vector<Eigen::Vector3f> before = model.mesh.vertices;
    model.levelling =
        LevelOntoSupport(options.support, grid.voxel_size(), options.level_band, &model.mesh);
    if (options.undo_self_intersections && model.levelling.vertices > 0) {
      // Where levelling made triangles pass through each other, those vertices go back. The mesh
      // had none before (when pairs_after is 0), so only the levelled vertices' triangles count.
      std::vector<uint8_t> levelled(before.size(), 0);
      for (size_t v = 0; v < before.size(); ++v) {
        levelled[v] = model.mesh.vertices[v] != before[v] ? 1 : 0;
      }
      undo.moved = model.self_intersections.pairs_after == 0 ? &levelled : nullptr;
      undo.progress = [&options](const std::string& line) {
        Tell(options, "mesh levelling: " + line);
      };
      const SelfIntersectionRepair undone = UndoSelfIntersections(before, &model.mesh, undo);
      model.levelling.undone = undone.vertices_moved_back;
      model.self_intersections.pairs_after = undone.pairs_after;
    }
    Tell(options, "mesh levelling: " + model.levelling.Summary());
  }
  MarkAndRemoveWalls(grid, views, options, &model);
  ColourModel(views, grid, options, &model);
  return model;
}

std::vector<ColouredPoint> SampleMeshPoints(const ModelMesh& model,
                                            double spacing,
                                            int min_views,
                                            uint64_t seed,
                                            std::vector<std::vector<uint32_t>>* visibility) {
  CHECK(spacing > 0.0);
  const TriangleMesh& mesh = model.mesh;
  CHECK(model.seen_by.size() == mesh.vertices.size());
  CHECK(mesh.normals.size() == mesh.vertices.size() && mesh.colours.size() == mesh.vertices.size());
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<ColouredPoint> points;
  if (visibility != nullptr) visibility->clear();
  const double per_area = 1.0 / (spacing * spacing);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[t[1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[t[2]].cast<double>();
    const double expected = 0.5 * (b - a).cross(c - a).norm() * per_area;
    int count = static_cast<int>(expected);
    if (uniform(random) < expected - count) ++count;
    for (int k = 0; k < count; ++k) {
      // Uniform over the triangle.
      double u = uniform(random), v = uniform(random);
      if (u + v > 1.0) {
        u = 1.0 - u;
        v = 1.0 - v;
      }
      const double w[3] = {1.0 - u - v, u, v};
      const int nearest = w[0] >= w[1] && w[0] >= w[2] ? 0 : (w[1] >= w[2] ? 1 : 2);
      const std::vector<uint32_t>& seen = model.seen_by[t[nearest]];
      if (static_cast<int>(seen.size()) < min_views) continue;
      if (!model.on_grid_wall.empty() && model.on_grid_wall[t[nearest]] != 0) continue;
      Eigen::Vector3d position = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero(),
                      colour = Eigen::Vector3d::Zero();
      for (int j = 0; j < 3; ++j) {
        position += w[j] * mesh.vertices[t[j]].cast<double>();
        normal += w[j] * mesh.normals[t[j]].cast<double>();
        colour += w[j] * mesh.colours[t[j]].cast<double>();
      }
      if (!(normal.norm() > 1e-6)) continue;
      ColouredPoint point;
      point.xyz = position.cast<float>();
      point.normal = normal.normalized().cast<float>();
      point.rgb = ToRgb(colour.cast<float>());
      points.push_back(point);
      if (visibility != nullptr) visibility->push_back(seen);
    }
  }
  return points;
}

void WritePointVisibility(const std::vector<std::vector<uint32_t>>& visibility, const std::string& path) {
  const std::string temporary = TemporaryPathFor(path);
  errno = 0;
  std::ofstream file(temporary, std::ios::binary);
  auto put = [&file](auto value) {
    // Little-endian on every platform this builds for (x86-64, arm64).
    file.write(reinterpret_cast<const char*>(&value), sizeof(value));
  };
  put(static_cast<uint64_t>(visibility.size()));
  for (const std::vector<uint32_t>& images : visibility) {
    put(static_cast<uint32_t>(images.size()));
    for (uint32_t image : images) put(image);
  }
  file.close();
  if (!file) ThrowWriteFailure(temporary, "the point visibility", errno);
  RenameIntoPlace(temporary, path);
}

}  // namespace exporter
}  // namespace raycarve
