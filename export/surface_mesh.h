#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "carve/volume.h"

namespace raycarve {
namespace exporter {

// A welded triangle mesh: each vertex is stored once and shared by the triangles around it.
// World coordinates of the model.
struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3f> normals;                  // unit, outward; one per vertex
  std::vector<Eigen::Matrix<uint8_t, 3, 1>> colours;     // RGB per vertex; empty until coloured
  std::vector<Eigen::Vector3i> triangles;                // counter-clockwise seen from outside
  // A texture (TextureMeshFromPhotos), or none: per triangle its three corners' coordinates in
  // `texture` (u right, v down, both 0-1 over the whole image, as glTF has them; pixel centres at
  // (i + 0.5) / size), and the atlas (CV_8UC3, RGB). Steps that change the triangles drop them.
  std::vector<Eigen::Vector2f> corner_uvs;
  cv::Mat texture;

  bool empty() const { return triangles.empty(); }
  bool textured() const {
    return !texture.empty() && corner_uvs.size() == 3 * triangles.size();
  }
};

// How the carved volume becomes a smooth surface.
struct SurfaceMeshOptions {
  // Windowed-sinc smoothing of the iso-surface (VTK's vtkWindowedSincPolyDataFilter): passes,
  // and the pass band (0-2; smaller smooths more). The iso-surface of solid/empty voxels is
  // stair-stepped at the voxel size; smoothing takes the steps off without shrinking it.
  int smoothing_iterations = 20;
  double smoothing_pass_band = 0.05;
  // Edges longer than this (world units) are split until none is (0: none split), so that
  // vertex colours can carry detail finer than a voxel.
  double max_edge_length = 0.0;
  // At most this many triangles (0: no budget): the mesh is decimated with its topology kept
  // (VTK's vtkDecimatePro), and edges are split only as far as the budget allows.
  int64_t max_triangles = 0;

  bool IsValid(std::string* reason) const;
};

struct SurfaceMeshSummary {
  int64_t iso_surface_triangles = 0;  // before splitting and decimation
  int64_t triangles = 0;
  int64_t vertices = 0;
  double seconds = 0.0;
  std::string Summary() const;
};

// The surface of the solid voxels as one welded, closed, 2-manifold triangle mesh: the
// iso-surface at occupancy 1/2 (VTK's flying edges; space outside the grid counts as empty, so
// the mesh is closed where the volume meets the grid's border), smoothed, split and decimated as
// the options say, with outward vertex normals (the faces' unit normals averaged, as VTK's
// vtkPolyDataNormals averages them; the winding is flying edges', which faces away from the solid
// voxels). Colours are left empty. An empty volume gives an empty mesh. `iso_surface`, when
// given, gets each vertex's position before smoothing (the iso-surface, which never folds through
// itself), index for index; empty when splitting or decimation changed the vertices.
TriangleMesh MeshSolidVoxels(const Volume& volume,
                             const SurfaceMeshOptions& options,
                             SurfaceMeshSummary* summary = nullptr,
                             std::vector<Eigen::Vector3f>* iso_surface = nullptr);

// How many threads the libraries' own parallel loops may use, process-wide: OpenCV's (resizing,
// filtering) and VTK's (the iso-surface, smoothing), which otherwise take every core whatever
// --num_threads says. `num_threads` < 1: one per core this process may use.
void SetLibraryThreads(int num_threads);

// Windowed-sinc smoothing (as MeshSolidVoxels smooths the iso-surface) of an existing mesh's
// vertices: `iterations` passes at `pass_band` (0-2; smaller smooths more). Vertices and
// triangles keep their indices and count; normals are recomputed; colours are kept.
void SmoothMesh(int iterations, double pass_band, TriangleMesh* mesh);

// How a vertex normal weighs the triangles around it: by area, or each face once (its unit
// normal), as VTK's vtkPolyDataNormals does. MeshSolidVoxels takes the latter, as the VTK
// filter it replaced did (measured: the same held-out figures on the six Middlebury models).
enum class NormalWeighting { kByArea, kPerFace };

// Sets every vertex normal to the weighted mean of its triangles' normals (the winding's side),
// normalised; a vertex in no triangle of non-zero area keeps a zero normal.
void ComputeVertexNormals(TriangleMesh* mesh, NormalWeighting weighting = NormalWeighting::kByArea);

// Per vertex, its neighbours along the triangles' edges: a vertex listed once per triangle edge
// it shares (twice for an interior edge of a closed mesh).
std::vector<std::vector<int>> VertexNeighbours(const TriangleMesh& mesh);

// `passes` times, each value becomes the mean of itself and its neighbours' (VertexNeighbours),
// on `num_threads` threads (< 1: one per core; the same values for any count).
void AverageOverNeighbours(const std::vector<std::vector<int>>& neighbours, int passes,
                           std::vector<float>* values, int num_threads = 1);

// Each vertex's connected part (through shared vertices), numbered 0, 1, ... in the order of
// each part's first vertex; `num_parts` gets the count.
std::vector<int> ConnectedParts(const TriangleMesh& mesh, int* num_parts);

// Keeps the vertices whose part (ConnectedParts) `keep` marks, and the triangles among them;
// normals and colours follow.
void KeepParts(const std::vector<int>& part, const std::vector<uint8_t>& keep, TriangleMesh* mesh);

// Removes every connected component (through shared vertices) with fewer than `min_vertices`
// vertices, and the vertices only they used (normals and colours follow). Returns the components
// removed.
int64_t RemoveSmallComponents(int64_t min_vertices, TriangleMesh* mesh);

// The mesh's topology, counted from its triangles.
struct MeshTopology {
  int64_t edges = 0;
  int64_t boundary_edges = 0;      // in one triangle only
  int64_t non_manifold_edges = 0;  // in three or more triangles
  int64_t non_manifold_vertices = 0;  // whose triangles form more than one fan
  int64_t inconsistent_edges = 0;  // shared by two triangles that run it the same way
  int64_t components = 0;          // connected through shared vertices
  int64_t degenerate_triangles = 0;  // repeating a vertex
  // Pairs of triangles that pass through each other (FindSelfIntersections): a mesh folded
  // through itself encloses no volume, whatever its edges say.
  int64_t self_intersecting_pairs = 0;
  // Every edge in exactly two triangles that run it in opposite directions, every vertex one fan,
  // and no triangle through another: a closed, oriented 2-manifold that bounds a solid.
  bool IsClosedManifold() const {
    return boundary_edges == 0 && non_manifold_edges == 0 && non_manifold_vertices == 0 &&
           inconsistent_edges == 0 && degenerate_triangles == 0 && self_intersecting_pairs == 0;
  }
  // What IsClosedManifold found wrong, e.g. "12 boundary edges, 3 pairs of triangles through
  // each other"; empty when nothing.
  std::string Faults() const;
};
// Counts the mesh's topology and its self-intersections (FindSelfIntersections), unless
// `known_self_intersections` (>= 0) gives their count: e.g. 0 after UndoSelfIntersections left
// none and only triangles were removed since, which cannot make new ones.
MeshTopology AnalyseTopology(const TriangleMesh& mesh, int64_t known_self_intersections = -1);

// Writes the mesh as binary little-endian PLY through PCL: vertex x y z nx ny nz red green blue
// (grey 128 where `colours` is empty), face vertex_indices. An empty mesh gives a valid PLY with
// no vertices and no faces. Written to a temporary name and renamed; throws InputError naming
// the path on failure.
void WriteMeshPly(const TriangleMesh& mesh, const std::string& path);

// Reads a PLY mesh or point cloud to draw (what `holdout --model` scores): vertex positions,
// colours where the file has them (grey 128 otherwise), polygons fanned into triangles (none for
// a cloud), normals recomputed from the faces. Vertices with a non-finite coordinate are
// refused. Throws InputError naming the path when it is missing, PCL cannot parse it, a face
// refers to a vertex that is not there, or there is nothing to draw.
TriangleMesh ReadMeshOrCloudPly(const std::string& path);

}  // namespace exporter
}  // namespace raycarve
