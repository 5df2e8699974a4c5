#pragma once

#include <functional>
#include <string>
#include <vector>

#include "carve/carver.h"
#include "carve/ground.h"
#include "calib/calibrated_view.h"
#include "export/mesh_colouring.h"
#include "export/mesh_exclusions.h"
#include "export/mesh_refinement.h"
#include "export/mesh_silhouettes.h"
#include "export/point_cloud_io.h"
#include "export/mesh_self_intersection.h"
#include "export/mesh_texture.h"
#include "export/support_levelling.h"
#include "export/surface_mesh.h"

namespace raycarve {
namespace exporter {

// The carved model as a coloured point cloud: one point per surface voxel seen by at least
// `min_views` views (voxels seen by fewer could not be judged and are left out), at the voxel's
// centre, with its colour and an outward normal (towards the empty side: the sum of
// the offsets to the empty or outside voxels among its 26 neighbours, normalised; zero when
// enclosed). World coordinates of the model.
std::vector<ColouredPoint> SurfacePoints(const CarveResult& result, int min_views);

struct MeshSummary {
  size_t num_vertices = 0;
  size_t num_triangles = 0;
};

// The carved volume as a triangle mesh: two triangles per voxel face between a solid voxel and
// an empty or outside one, with the solid voxel's colour on the face's 4 vertices (grey for a
// voxel no view sees). Written through PCL as binary PLY (vertex x y z red green blue; faces),
// under a temporary name and renamed. Throws InputError naming the path on failure.
MeshSummary WriteVoxelMeshPly(const CarveResult& result, const std::string& path);

// What the user takes away: the carved volume as a smooth welded mesh coloured from the photos.
struct ModelMeshOptions {
  // Edges are split until none is longer than this many photo pixels (the median over the views
  // of a pixel's width at the volume's centre), so that colours can carry detail finer than the
  // iso-surface's spacing (about a voxel). Never finer than a quarter of a voxel. 0: no
  // splitting, the default: at 2 pixels the Middlebury sets' held-out PSNR fell (dinoRing 20.05
  // to 19.88 dB, templeSparseRing 15.66 to 15.54) for 5x the triangles and time, because the
  // geometry's error, not the vertex spacing, limits the colours there.
  double edge_pixels = 0.0;
  int64_t max_triangles = 0;      // face budget (0: none)
  int smoothing_iterations = 20;  // windowed-sinc passes (0: the stair-stepped iso-surface)
  int min_views = 2;              // vertices seen by fewer photos take their neighbours' colour
  // Passes of RefineMeshFromPhotos (search +-1 voxel along the normals, or further: below;
  // patches half a voxel across) before colouring, at most; 0: the smoothed iso-surface as it
  // is. They stop after the first pass that moves the vertices by less than
  // `refine_converged_voxels` voxels on average.
  // The surface the carve leaves lies more voxels out on a finer grid: on the paper's generated
  // scene the mean |offset| per pass fell below 0.1 voxel after 3 passes at 128 voxels and 5 at
  // 256; two passes (the earlier fixed count) left 256's cloud at 94.0% completeness and 87.4%
  // precision, four give 95.9% and 91.1%. On the Middlebury sets the passes do not converge as
  // fast (the mean |offset| stays above 0.1 voxel for 4-7 passes over their plain surfaces) and
  // passes beyond four cost held-out PSNR (dinoRing at 256 voxels: 21.00 dB after 4, 20.70 after
  // 7), so four is the most (docs/studies/mesh.md).
  int refine_passes = 4;
  double refine_converged_voxels = 0.1;
  // Each pass searches +-1 voxel along the normals; on a grid finer than the photos (a voxel
  // narrower than a pixel: the median over the views of a pixel's width at the volume's centre)
  // +-this many pixels instead, where that is further. The photos can only tell apart offsets
  // that move the surface's image by a pixel or more: there a voxel's search left most vertices
  // unjudged or judged on noise. Held out, every 4th photo, 512 voxels (0.94 px): dinoSparseRing
  // 17.66 -> 18.05 dB, templeSparseRing 16.12 -> 16.37; paper scene F-score 94.05 -> 94.44%;
  // a generated ring of 8 photos of 240x180 at 256 voxels (0.56 px) 84.2 -> 86.5%. Where a voxel
  // spans 1.1-1.3 pixels the wider search cost F-score on generated scenes (8 photos of 240x180
  // at 128: 97.5 -> 96.4%; the room ring at 512: 83.8 -> 82.3%), so a voxel of a pixel or more
  // keeps its own search (docs/studies/2026-12-07-refinement-search.md). 0: a voxel always.
  double refine_search_pixels = 3.0;
  // After refinement, each vertex moves towards the mesh smoothed again (windowed sinc, this
  // many passes at the first smoothing's pass band), by the share the photos leave open:
  // 1 - MeshRefinementSummary::pinned. Where the photos place a vertex (texture, a clear cost
  // minimum) it stays; over plain surfaces and where too few photos see it, the voxels' bumps
  // the carve left are smoothed out. 0: none. Held-out PSNR of the mesh at 128 voxels, defaults
  // otherwise: +0.09 to +0.58 dB on the six Middlebury models; on the generated scenes the
  // objects' precision rises at 128 voxels and falls at 256 (docs/studies/mesh.md).
  int final_smoothing_iterations = 40;
  // Pieces of the iso-surface with fewer vertices than this go before refinement: specks, and
  // the parts of specks that flying edges splits where voxels touch only along an edge or at a
  // corner. 24 is the iso-surface of a 2x2x2 block, the smallest speck the carve's default
  // --min_component_voxels 8 keeps; 0 keeps everything.
  int64_t min_component_vertices = 24;
  // After refinement, smoothing and the silhouette fit, triangles that pass through each other
  // are undone (UndoSelfIntersections: their vertices move back towards the iso-surface before
  // refinement), so that the mesh bounds a solid. Off: the mesh as refined.
  bool undo_self_intersections = true;
  // Then parts of the iso-surface that fewer than this many masked photos need go
  // (RemoveUnneededParts: the visual hull's phantoms, pieces every photo sees within the object's
  // silhouette); the largest part stays. 0 keeps every part. Two photos, as elsewhere: one photo's
  // mask can be wrong, and the silhouette repair serves one photo's object pixels at a time.
  int part_min_views = 2;
  // Reliable sparse points: a part within 1.5 voxels of one stays (RemoveUnneededParts).
  std::vector<Eigen::Vector3d> sparse_points;
  // After the final smoothing, passes of FitMeshToSilhouettes: outline vertices standing beyond
  // the masks are pulled in onto their edges (by the median over the photos they are on the
  // outline of, at most a voxel a pass). 0: none.
  int silhouette_passes = 2;
  // Triangles on the grid's wall (ModelMesh::on_grid_wall: all three corners on it) are left
  // out of the mesh: the box cuts the scene there (a table or the ground running on beyond it,
  // a backdrop the views see through it), which has no surface on the wall; the mesh is open
  // where the box cuts. The box comes from the sparse points with a margin, so it does not lie
  // on a surface they saw. false: kept, the mesh closed by the box.
  bool remove_grid_walls = true;
  // With remove_grid_walls, the surface beyond the photos' frames (UncoveredVertices with
  // min_views) is left out with the walls too.
  // With remove_grid_walls, on a capture from one side (a scene), the surface that fewer than
  // min_views photos see, the model's own occlusion included (UnseenVertices), is left out with
  // the walls too: behind each subject, where every camera's view is blocked, the carve judged
  // nothing and kept the space solid, a fin of the subject's shadow running on to the box's far
  // side. Off for an object (cameras around it), whose closed mesh keeps what it hides (its foot).
  bool remove_unseen = false;
  // The ground the carve held (CarveOptions::ground): with remove_grid_walls, the held solid's
  // sides and underside below the plane (GroundFillVertices) are left out with the walls: they
  // stand for no surface the photos saw. Empty: none.
  Ground ground;
  // The plane the subject stands on where the sparse points show it (its footprint), held or
  // not: after the silhouette fit, the mesh within two voxels of it, or `level_band` where that is
  // wider, is levelled onto it (LevelOntoSupport). Empty: not levelled.
  Ground support;
  double level_band = 0.0;  // world units; 0: two voxels
  // Threads for refining and colouring (0 or less: every core); the mesh does not depend on it.
  int num_threads = 0;
  // After colouring, a texture atlas from the photos (TextureMeshFromPhotos): each triangle
  // coloured from the photo that sees it best, at the photo's resolution. false: vertex colours
  // only.
  bool texture = true;
  MeshTextureOptions texture_options;
  // Told a line as each step starts or ends (what it did), so that a long mesh stage shows its
  // progress; empty: nothing told.
  std::function<void(const std::string&)> progress;
  bool IsValid(std::string* reason) const;
};
struct ModelMesh {
  TriangleMesh mesh;
  SurfaceMeshSummary geometry;
  int64_t small_components_removed = 0;
  MeshRefinementSummary refinement;
  double final_smoothing_mean_move = 0.0;  // world units, over all vertices
  MeshPartsSummary parts;
  SilhouetteFitSummary silhouettes;
  SupportLevelling levelling;
  SelfIntersectionRepair self_intersections;
  MeshColouringSummary colouring;
  MeshTextureSummary texture;
  std::vector<std::vector<uint32_t>> seen_by;  // per vertex, the views (indices) that see it
  // Per vertex, 1 where it lies on the grid's wall: the part of the surface that separates solid
  // voxels from the space outside the grid (which the mesh treats as empty so that it closes).
  // That is where the volume's box cuts the scene (a table or ground running on beyond it), not
  // a surface: the photos see the scene beyond the box through it. Within 1.5 voxels of one of
  // the box's faces, with the normal at most 60 degrees from that face's outward direction.
  std::vector<uint8_t> on_grid_wall;
  int64_t grid_wall_vertices = 0;    // before the wall's triangles are left out
  int64_t wall_triangles_removed = 0;
  int64_t wall_sliver_triangles_removed = 0;  // specks the walls' removal left (not counted above)
  int64_t triangles_before_walls = 0;
  // Of wall_triangles_removed, those of the ground's fill (all three corners GroundFillVertices)
  // that were not on the walls as well.
  int64_t ground_fill_triangles_removed = 0;
  // Of wall_triangles_removed, those beyond the photos' frames (all three corners
  // UncoveredVertices) that were neither on the walls nor of the ground's fill.
  int64_t uncovered_triangles_removed = 0;
  // Of wall_triangles_removed, those fewer than min_views photos see (all three corners
  // UnseenVertices, with ModelMeshOptions::remove_unseen) that none of the above took.
  int64_t unseen_triangles_removed = 0;
  // Vertices fewer than min_views photos see that stayed, within a voxel of what they see
  // (KeepUnseenNearSeen).
  int64_t unseen_vertices_kept = 0;
};

// Leaves out the triangles whose three corners are on the grid's wall (model->on_grid_wall),
// then the parts that become specks without them (SpeckVertices: under 1% of the largest part,
// no anchor of `anchors` within `anchor_radius` nearer to them than to the largest part), and
// the vertices no triangle uses any more (with their per-vertex data), counting them.
void RemoveGridWalls(ModelMesh* model, const std::vector<Eigen::Vector3d>& anchors = {},
                     double anchor_radius = 0.0);
// One line on the smoothing after refinement: passes, the photos' mean pin, the mean move.
std::string FinalSmoothingSummary(const ModelMesh& model, const ModelMeshOptions& options);

// Meshes the result's solid voxels (MeshSolidVoxels), refines the mesh along its normals
// (RefineMeshFromPhotos), smooths it where the photos leave its position open
// (final_smoothing_iterations), and colours it from `views` (ColourMeshFromPhotos, depth
// tolerance one voxel); marks the vertices on the grid's wall.
ModelMesh MeshCarvedModel(const CarveResult& result,
                          const std::vector<CalibratedView>& views,
                          const ModelMeshOptions& options);

// The model's cloud, sampled on its smooth mesh about one point per `spacing` x `spacing` of
// surface (a photo pixel's footprint gives the density of COLMAP's own fused clouds, which its
// meshers' defaults expect), at fixed pseudo-random places (`seed`) in each triangle, with the
// blend of the triangle's vertex colours and normals (unit, outward). A point is kept where its
// nearest corner is seen by `min_views` or more photos and does not lie on the grid's wall
// (ModelMesh::on_grid_wall); `visibility` gets, per point, the indices of the views that see that
// corner (ModelMesh::seen_by).
std::vector<ColouredPoint> SampleMeshPoints(const ModelMesh& model,
                                            double spacing,
                                            int min_views,
                                            uint64_t seed,
                                            std::vector<std::vector<uint32_t>>* visibility);

// Writes COLMAP's point visibility file (what it writes as fused.ply.vis beside a fused cloud):
// little-endian uint64 point count, then per point a uint32 count and that many uint32 image
// indices (positions in the dense workspace's image list). Written to a temporary name and
// renamed; throws InputError naming the path on failure.
void WritePointVisibility(const std::vector<std::vector<uint32_t>>& visibility, const std::string& path);

}  // namespace exporter
}  // namespace raycarve
