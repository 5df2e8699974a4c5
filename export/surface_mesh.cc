#include "export/surface_mesh.h"
#include "export/mesh_self_intersection.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <unordered_map>
#include <utility>

#include <glog/logging.h>
#include <opencv2/core.hpp>
#include <pcl/PolygonMesh.h>
#include <pcl/console/print.h>
#include <pcl/conversions.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <vtkAdaptiveSubdivisionFilter.h>
#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkDecimatePro.h>
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSMPTools.h>
#include <vtkSmartPointer.h>
#include <vtkWindowedSincPolyDataFilter.h>

#include "calib/atomic_file.h"
#include "calib/input_error.h"
#include "carve/view_workers.h"
#include "export/parallel_ranges.h"
#include "export/ply_reader.h"
#include "export/point_cloud_io.h"

// A mesh vertex as the PLY holds it: position, normal, colour (PCL packs red, green and blue into
// one float field named rgb and writes them as three uchar properties).
struct EIGEN_ALIGN16 MeshVertex {
  PCL_ADD_POINT4D;
  PCL_ADD_NORMAL4D;
  PCL_ADD_RGB;
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};
POINT_CLOUD_REGISTER_POINT_STRUCT(MeshVertex,
                                  (float, x, x)(float, y, y)(float, z, z)
                                  (float, normal_x, normal_x)(float, normal_y, normal_y)
                                  (float, normal_z, normal_z)(float, rgb, rgb))

namespace raycarve {
namespace exporter {
namespace {

TriangleMesh FromPolyData(vtkPolyData* poly) {
  TriangleMesh mesh;
  vtkPoints* points = poly->GetPoints();
  const vtkIdType num_points = points == nullptr ? 0 : points->GetNumberOfPoints();
  mesh.vertices.resize(num_points);
  for (vtkIdType i = 0; i < num_points; ++i) {
    double p[3];
    points->GetPoint(i, p);
    mesh.vertices[i] = Eigen::Vector3f(static_cast<float>(p[0]), static_cast<float>(p[1]),
                                       static_cast<float>(p[2]));
  }
  vtkDataArray* normals = poly->GetPointData()->GetNormals();
  if (normals != nullptr && normals->GetNumberOfTuples() == num_points) {
    mesh.normals.resize(num_points);
    for (vtkIdType i = 0; i < num_points; ++i) {
      double n[3];
      normals->GetTuple(i, n);
      mesh.normals[i] = Eigen::Vector3d(n[0], n[1], n[2]).normalized().cast<float>();
    }
  }
  vtkCellArray* polys = poly->GetPolys();
  mesh.triangles.reserve(polys->GetNumberOfCells());
  vtkIdType count = 0;
  const vtkIdType* ids = nullptr;
  for (polys->InitTraversal(); polys->GetNextCell(count, ids);) {
    if (count != 3) continue;  // flying edges and the filters after it make triangles only
    mesh.triangles.emplace_back(static_cast<int>(ids[0]), static_cast<int>(ids[1]),
                                static_cast<int>(ids[2]));
  }
  return mesh;
}

// VTK's windowed-sinc smoothing of a triangle surface, as every mesh here is smoothed: interior
// vertices only move, feature edges are not held, non-manifold vertices are smoothed too.
vtkSmartPointer<vtkPolyData> WindowedSinc(vtkPolyData* surface, int iterations, double pass_band) {
  vtkNew<vtkWindowedSincPolyDataFilter> smoother;
  smoother->SetInputData(surface);
  smoother->SetNumberOfIterations(iterations);
  smoother->SetPassBand(pass_band);
  smoother->BoundarySmoothingOff();
  smoother->FeatureEdgeSmoothingOff();
  smoother->NonManifoldSmoothingOn();
  smoother->NormalizeCoordinatesOn();
  smoother->Update();
  return smoother->GetOutput();
}

}  // namespace

bool SurfaceMeshOptions::IsValid(std::string* reason) const {
  if (smoothing_iterations < 0) {
    *reason = "mesh smoothing iterations must be >= 0";
    return false;
  }
  if (!(smoothing_pass_band > 0.0 && smoothing_pass_band <= 2.0)) {
    *reason = "mesh smoothing pass band must lie in (0, 2]";
    return false;
  }
  if (!(max_edge_length >= 0.0) || !std::isfinite(max_edge_length)) {
    *reason = "mesh maximum edge length must be >= 0";
    return false;
  }
  if (max_triangles < 0 || (max_triangles > 0 && max_triangles < 4)) {
    *reason = "mesh face budget must be 0 (none) or at least 4";
    return false;
  }
  return true;
}

std::string SurfaceMeshSummary::Summary() const {
  char text[200];
  std::snprintf(text, sizeof(text), "mesh: %lld triangles, %lld vertices (iso-surface %lld) in %.2f s",
                static_cast<long long>(triangles), static_cast<long long>(vertices),
                static_cast<long long>(iso_surface_triangles), seconds);
  return text;
}

namespace {

// The volume's solid voxels as a VTK image of 0/1, with one voxel of empty space all round so
// that the surface closes at the grid's border; *solid counts them.
vtkSmartPointer<vtkImageData> OccupancyImage(const Volume& volume, int64_t* solid_count) {
  const VoxelGrid& grid = volume.grid();
  const Eigen::Vector3i dims = grid.dimensions();
  // One voxel of empty space all round, so that the surface closes at the grid's border.
  const Eigen::Vector3i padded = dims + Eigen::Vector3i::Constant(2);
  const double size = grid.voxel_size();
  vtkSmartPointer<vtkImageData> image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(padded.x(), padded.y(), padded.z());
  image->SetSpacing(size, size, size);
  const Eigen::Vector3d first = grid.Centre(Eigen::Vector3i(-1, -1, -1));
  image->SetOrigin(first.x(), first.y(), first.z());
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  auto* occupancy = static_cast<unsigned char*>(image->GetScalarPointer());
  std::fill(occupancy, occupancy + static_cast<int64_t>(padded.x()) * padded.y() * padded.z(), 0);
  int64_t& solid = *solid_count;
  solid = 0;
  for (int z = 0; z < dims.z(); ++z) {
    for (int y = 0; y < dims.y(); ++y) {
      for (int x = 0; x < dims.x(); ++x) {
        if (!volume.IsSolid(grid.Index(Eigen::Vector3i(x, y, z)))) continue;
        occupancy[(x + 1) + static_cast<int64_t>(padded.x()) *
                                ((y + 1) + static_cast<int64_t>(padded.y()) * (z + 1))] = 1;
        ++solid;
      }
    }
  }
  return image;
}

// Splits the surface's edges longer than options.max_edge_length, only as far as
// options.max_triangles allows: each split at least halves an edge, and triangles grow with
// (mean edge / max edge)^2.
vtkSmartPointer<vtkPolyData> SplitLongEdges(vtkSmartPointer<vtkPolyData> surface,
                                            const SurfaceMeshOptions& options) {
  // Each split at least halves an edge; estimate the triangles it would make from the mean
  // edge length, and split only as far as the budget allows.
  double edge_sum = 0.0;
  int64_t edge_count = 0;
  vtkCellArray* polys = surface->GetPolys();
  vtkIdType count = 0;
  const vtkIdType* ids = nullptr;
  for (polys->InitTraversal(); polys->GetNextCell(count, ids);) {
    for (vtkIdType k = 0; k < count; ++k) {
      double a[3], b[3];
      surface->GetPoint(ids[k], a);
      surface->GetPoint(ids[(k + 1) % count], b);
      edge_sum += std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                            (a[2] - b[2]) * (a[2] - b[2]));
      ++edge_count;
    }
  }
  double edge = options.max_edge_length;
  if (options.max_triangles > 0 && edge_count > 0) {
    const double mean_edge = edge_sum / edge_count;
    const double growth = static_cast<double>(options.max_triangles) /
                          std::max<int64_t>(1, surface->GetNumberOfPolys());
    // Triangles grow with (mean edge / max edge)^2.
    edge = std::max(edge, mean_edge / std::sqrt(std::max(growth, 1.0)));
  }
  vtkNew<vtkAdaptiveSubdivisionFilter> splitter;
  splitter->SetInputData(surface);
  splitter->SetMaximumEdgeLength(edge);
  splitter->Update();
  surface = splitter->GetOutput();
  return surface;
}

// Decimates the surface to options.max_triangles, keeping its topology and boundary.
vtkSmartPointer<vtkPolyData> Decimate(vtkSmartPointer<vtkPolyData> surface,
                                      const SurfaceMeshOptions& options) {
  vtkNew<vtkDecimatePro> decimate;
  decimate->SetInputData(surface);
  decimate->SetTargetReduction(1.0 - static_cast<double>(options.max_triangles) /
                                         surface->GetNumberOfPolys());
  decimate->PreserveTopologyOn();
  decimate->SplittingOff();
  decimate->BoundaryVertexDeletionOff();
  decimate->Update();
  surface = decimate->GetOutput();
  return surface;
}

}  // namespace

TriangleMesh MeshSolidVoxels(const Volume& volume,
                             const SurfaceMeshOptions& options,
                             SurfaceMeshSummary* summary,
                             std::vector<Eigen::Vector3f>* iso_surface) {
  if (iso_surface != nullptr) iso_surface->clear();
  const auto start = std::chrono::steady_clock::now();
  SurfaceMeshSummary local;
  SurfaceMeshSummary& result = summary != nullptr ? *summary : local;
  result = SurfaceMeshSummary();
  int64_t solid = 0;
  const vtkSmartPointer<vtkImageData> image = OccupancyImage(volume, &solid);
  if (solid == 0) {
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return TriangleMesh();
  }

  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(image);
  contour->SetValue(0, 0.5);
  contour->ComputeNormalsOff();
  contour->ComputeGradientsOff();
  contour->ComputeScalarsOff();
  contour->Update();
  vtkSmartPointer<vtkPolyData> surface = contour->GetOutput();
  result.iso_surface_triangles = surface->GetNumberOfPolys();
  // Smoothing moves the points and keeps their order; splitting and decimation do not.
  const bool same_points = options.max_edge_length <= 0.0 &&
                           !(options.max_triangles > 0 &&
                             surface->GetNumberOfPolys() > options.max_triangles);
  if (iso_surface != nullptr && same_points) *iso_surface = FromPolyData(surface).vertices;

  if (options.smoothing_iterations > 0) {
    surface = WindowedSinc(surface, options.smoothing_iterations, options.smoothing_pass_band);
  }

  if (options.max_edge_length > 0.0) surface = SplitLongEdges(surface, options);

  if (options.max_triangles > 0 && surface->GetNumberOfPolys() > options.max_triangles) {
    surface = Decimate(surface, options);
  }

  // Flying edges winds every triangle with the occupancy's gradient, facing away from the solid
  // side (a cavity's faces included), and the smoothing, splitting and decimation after it keep
  // the winding: the normals follow from the triangles as they are.
  TriangleMesh mesh = FromPolyData(surface);
  ComputeVertexNormals(&mesh, NormalWeighting::kPerFace);
  result.triangles = static_cast<int64_t>(mesh.triangles.size());
  result.vertices = static_cast<int64_t>(mesh.vertices.size());
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return mesh;
}

void SetLibraryThreads(int num_threads) {
  const int threads = ResolveNumThreads(num_threads);
  cv::setNumThreads(threads);
  vtkSMPTools::Initialize(threads);
}

void SmoothMesh(int iterations, double pass_band, TriangleMesh* mesh) {
  CHECK(iterations >= 0 && pass_band > 0.0 && pass_band <= 2.0);
  if (iterations == 0 || mesh->triangles.empty()) return;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh->vertices.size()));
  for (size_t i = 0; i < mesh->vertices.size(); ++i) {
    const Eigen::Vector3f& v = mesh->vertices[i];
    points->SetPoint(static_cast<vtkIdType>(i), v.x(), v.y(), v.z());
  }
  vtkNew<vtkCellArray> cells;
  for (const Eigen::Vector3i& t : mesh->triangles) {
    const vtkIdType ids[3] = {t[0], t[1], t[2]};
    cells->InsertNextCell(3, ids);
  }
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(points);
  poly->SetPolys(cells);
  const vtkSmartPointer<vtkPolyData> output = WindowedSinc(poly, iterations, pass_band);
  vtkPoints* smoothed = output->GetPoints();
  // The filter moves points and keeps their order.
  CHECK(smoothed != nullptr &&
        smoothed->GetNumberOfPoints() == static_cast<vtkIdType>(mesh->vertices.size()));
  for (size_t i = 0; i < mesh->vertices.size(); ++i) {
    double p[3];
    smoothed->GetPoint(static_cast<vtkIdType>(i), p);
    mesh->vertices[i] = Eigen::Vector3d(p[0], p[1], p[2]).cast<float>();
  }
  ComputeVertexNormals(mesh);
}

void ComputeVertexNormals(TriangleMesh* mesh, NormalWeighting weighting) {
  std::vector<Eigen::Vector3d> sums(mesh->vertices.size(), Eigen::Vector3d::Zero());
  for (const Eigen::Vector3i& t : mesh->triangles) {
    const Eigen::Vector3d a = mesh->vertices[t[0]].cast<double>();
    const Eigen::Vector3d b = mesh->vertices[t[1]].cast<double>();
    const Eigen::Vector3d c = mesh->vertices[t[2]].cast<double>();
    Eigen::Vector3d normal = (b - a).cross(c - a);  // twice the area, along the normal
    if (weighting == NormalWeighting::kPerFace) {
      const double length = normal.norm();
      if (!(length > 0.0)) continue;
      normal /= length;
    }
    for (int k = 0; k < 3; ++k) sums[t[k]] += normal;
  }
  mesh->normals.resize(mesh->vertices.size());
  for (size_t i = 0; i < sums.size(); ++i) {
    const double norm = sums[i].norm();
    mesh->normals[i] = norm > 0.0 ? Eigen::Vector3f((sums[i] / norm).cast<float>()) : Eigen::Vector3f::Zero();
  }
}

std::vector<std::vector<int>> VertexNeighbours(const TriangleMesh& mesh) {
  // Counted first, so that each list is allocated once.
  std::vector<int> count(mesh.vertices.size(), 0);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) count[t[k]] += 2;
  }
  std::vector<std::vector<int>> neighbours(mesh.vertices.size());
  for (size_t i = 0; i < neighbours.size(); ++i) neighbours[i].reserve(count[i]);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      neighbours[t[k]].push_back(t[(k + 1) % 3]);
      neighbours[t[k]].push_back(t[(k + 2) % 3]);
    }
  }
  return neighbours;
}

void AverageOverNeighbours(const std::vector<std::vector<int>>& neighbours, int passes,
                           std::vector<float>* values, int num_threads) {
  const size_t n = values->size();
  const int threads = ResolveNumThreads(num_threads);
  std::vector<float> averaged(n);
  for (int pass = 0; pass < passes; ++pass) {
    // Each value from the previous pass's alone: the ranges do not depend on each other.
    ParallelRanges(n, threads, /*min_per_thread=*/8192, [&](size_t first, size_t last) {
      for (size_t i = first; i < last; ++i) {
        double sum = (*values)[i];
        for (int j : neighbours[i]) sum += (*values)[j];
        averaged[i] = static_cast<float>(sum / (1 + neighbours[i].size()));
      }
    });
    values->swap(averaged);
  }
}

std::vector<int> ConnectedParts(const TriangleMesh& mesh, int* num_parts) {
  const int n = static_cast<int>(mesh.vertices.size());
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&parent](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const Eigen::Vector3i& t : mesh.triangles) {
    parent[find(t[1])] = find(t[0]);
    parent[find(t[2])] = find(t[0]);
  }
  std::vector<int> part_of_root(n, -1), part(n);
  int parts = 0;
  for (int v = 0; v < n; ++v) {
    int& p = part_of_root[find(v)];
    if (p < 0) p = parts++;
    part[v] = p;
  }
  *num_parts = parts;
  return part;
}

void KeepParts(const std::vector<int>& part, const std::vector<uint8_t>& keep, TriangleMesh* mesh) {
  const int n = static_cast<int>(mesh->vertices.size());
  const bool normals = mesh->normals.size() == mesh->vertices.size();
  const bool colours = mesh->colours.size() == mesh->vertices.size();
  std::vector<int> remap(n, -1);
  TriangleMesh kept;
  for (int v = 0; v < n; ++v) {
    if (!keep[part[v]]) continue;
    remap[v] = static_cast<int>(kept.vertices.size());
    kept.vertices.push_back(mesh->vertices[v]);
    if (normals) kept.normals.push_back(mesh->normals[v]);
    if (colours) kept.colours.push_back(mesh->colours[v]);
  }
  for (const Eigen::Vector3i& t : mesh->triangles) {
    if (remap[t[0]] < 0) continue;
    kept.triangles.emplace_back(remap[t[0]], remap[t[1]], remap[t[2]]);
  }
  *mesh = std::move(kept);
}

int64_t RemoveSmallComponents(int64_t min_vertices, TriangleMesh* mesh) {
  int parts = 0;
  const std::vector<int> part = ConnectedParts(*mesh, &parts);
  std::vector<int64_t> size(parts, 0);
  for (int p : part) ++size[p];
  std::vector<uint8_t> keep(parts, 0);
  int64_t removed = 0;
  for (int p = 0; p < parts; ++p) {
    keep[p] = size[p] >= min_vertices;
    removed += !keep[p];
  }
  if (removed > 0) KeepParts(part, keep, mesh);
  return removed;
}

std::string MeshTopology::Faults() const {
  std::string text;
  const auto add = [&text](int64_t count, const std::string& what) {
    if (count == 0) return;
    text += (text.empty() ? "" : ", ") + std::to_string(count) + " " + what;
  };
  add(boundary_edges, "boundary edges");
  add(non_manifold_edges, "edges in 3+ triangles");
  add(non_manifold_vertices, "vertices where sheets touch");
  add(inconsistent_edges, "edges of flipped triangles");
  add(degenerate_triangles, "degenerate triangles");
  add(self_intersecting_pairs, "pairs of triangles through each other");
  return text;
}

MeshTopology AnalyseTopology(const TriangleMesh& mesh, int64_t known_self_intersections) {
  MeshTopology topology;
  topology.self_intersecting_pairs =
      known_self_intersections >= 0 ? known_self_intersections
                                    : static_cast<int64_t>(FindSelfIntersections(mesh).size());
  const int num_vertices = static_cast<int>(mesh.vertices.size());
  // Directed edges: key (min, max); count of uses and the balance of their directions.
  struct EdgeUse {
    int count = 0;
    int forward = 0;  // uses running min -> max
  };
  std::unordered_map<uint64_t, EdgeUse> edges;
  edges.reserve(mesh.triangles.size() * 2);
  std::vector<int> parent(num_vertices);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&parent](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  std::vector<bool> used(num_vertices, false);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      ++topology.degenerate_triangles;
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      const uint64_t key = (static_cast<uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
      EdgeUse& use = edges[key];
      ++use.count;
      if (a < b) ++use.forward;
      used[a] = true;
      parent[find(a)] = find(b);
    }
  }
  topology.edges = static_cast<int64_t>(edges.size());
  for (const auto& [key, use] : edges) {
    if (use.count == 1) ++topology.boundary_edges;
    if (use.count > 2) ++topology.non_manifold_edges;
    if (use.count == 2 && use.forward != 1) ++topology.inconsistent_edges;
  }
  for (int v = 0; v < num_vertices; ++v) {
    if (used[v] && find(v) == v) ++topology.components;
  }
  // Fans: around each vertex, its triangles joined through the edges they share at it.
  std::vector<std::vector<int>> around(num_vertices);
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const Eigen::Vector3i& t = mesh.triangles[i];
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) continue;
    for (int k = 0; k < 3; ++k) around[t[k]].push_back(static_cast<int>(i));
  }
  for (int v = 0; v < num_vertices; ++v) {
    const std::vector<int>& fan = around[v];
    if (fan.size() < 2) continue;
    // Union the triangles at v that share another vertex (the edge v-w).
    std::vector<int> group(fan.size());
    std::iota(group.begin(), group.end(), 0);
    auto root = [&group](int i) {
      while (group[i] != i) i = group[i] = group[group[i]];
      return i;
    };
    std::unordered_map<int, int> first_with;  // other vertex -> a triangle index in fan
    for (size_t i = 0; i < fan.size(); ++i) {
      const Eigen::Vector3i& t = mesh.triangles[fan[i]];
      for (int k = 0; k < 3; ++k) {
        if (t[k] == v) continue;
        auto [it, inserted] = first_with.emplace(t[k], static_cast<int>(i));
        if (!inserted) group[root(static_cast<int>(i))] = root(it->second);
      }
    }
    int roots = 0;
    for (size_t i = 0; i < fan.size(); ++i) {
      if (root(static_cast<int>(i)) == static_cast<int>(i)) ++roots;
    }
    if (roots > 1) ++topology.non_manifold_vertices;
  }
  return topology;
}

TriangleMesh ReadMeshOrCloudPly(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw InputError(path + ": file not found");
  PlyData data = ReadPly(path);  // non-finite coordinates and bad faces refused by name
  if (data.xyz.empty()) throw InputError(path + ": no vertices to draw");
  TriangleMesh mesh;
  mesh.vertices = std::move(data.xyz);
  if (data.rgb.empty()) {
    mesh.colours.assign(mesh.vertices.size(), Eigen::Matrix<uint8_t, 3, 1>::Constant(128));
  } else {
    mesh.colours = std::move(data.rgb);
  }
  mesh.triangles = std::move(data.triangles);
  ComputeVertexNormals(&mesh);
  return mesh;
}

void WriteMeshPly(const TriangleMesh& mesh, const std::string& path) {
  const std::string temporary = TemporaryPathFor(path);
  if (mesh.triangles.empty()) {
    // PCL refuses to write a mesh without vertices; an empty carve still gets a valid PLY with
    // the same elements and properties.
    errno = 0;
    std::ofstream file(temporary, std::ios::binary);
    file << "ply\nformat binary_little_endian 1.0\ncomment raycarve: empty mesh\nelement vertex 0\n"
            "property float x\nproperty float y\nproperty float z\nproperty float nx\n"
            "property float ny\nproperty float nz\nproperty uchar red\nproperty uchar green\n"
            "property uchar blue\nelement face 0\nproperty list uchar int vertex_indices\n"
            "end_header\n";
    file.close();
    if (!file) ThrowWriteFailure(temporary, "the mesh", errno);
    RenameIntoPlace(temporary, path);
    return;
  }
  pcl::PointCloud<MeshVertex> vertices;
  vertices.reserve(mesh.vertices.size());
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    MeshVertex v;
    v.x = mesh.vertices[i].x();
    v.y = mesh.vertices[i].y();
    v.z = mesh.vertices[i].z();
    const Eigen::Vector3f n = i < mesh.normals.size() ? mesh.normals[i] : Eigen::Vector3f::Zero();
    v.normal_x = n.x();
    v.normal_y = n.y();
    v.normal_z = n.z();
    if (i < mesh.colours.size()) {
      v.r = mesh.colours[i][0];
      v.g = mesh.colours[i][1];
      v.b = mesh.colours[i][2];
    } else {
      v.r = v.g = v.b = 128;
    }
    v.a = 255;
    vertices.push_back(v);
  }
  vertices.width = static_cast<uint32_t>(vertices.size());
  vertices.height = 1;
  pcl::PolygonMesh polygon_mesh;
  pcl::toPCLPointCloud2(vertices, polygon_mesh.cloud);
  polygon_mesh.polygons.reserve(mesh.triangles.size());
  for (const Eigen::Vector3i& t : mesh.triangles) {
    pcl::Vertices face;
    face.vertices = {static_cast<pcl::index_t>(t[0]), static_cast<pcl::index_t>(t[1]),
                     static_cast<pcl::index_t>(t[2])};
    polygon_mesh.polygons.push_back(face);
  }
  errno = 0;
  if (pcl::io::savePLYFileBinary(temporary, polygon_mesh) != 0) {
    ThrowWriteFailure(temporary, "the mesh (PCL)", errno);
  }
  RenameIntoPlace(temporary, path);
}

}  // namespace exporter
}  // namespace raycarve
