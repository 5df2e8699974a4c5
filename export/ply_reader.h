#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace raycarve {
namespace exporter {

// One PLY property: a scalar, or a list (a count, then that many items).
struct PlyProperty {
  std::string name;
  std::string type;        // the scalar's (or the list items') type, as PLY names it
  std::string count_type;  // lists only; empty for a scalar
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

// A PLY file's header, checked against the file before anything is sized from it.
struct PlyHeader {
  std::string format;  // ascii, binary_little_endian or binary_big_endian
  std::vector<PlyElement> elements;
  uint64_t header_bytes = 0;  // where the body starts
  uint64_t file_bytes = 0;
  uint64_t vertices = 0;      // the vertex element's count
};

// Reads and checks a PLY header: "ply", a known format, known property types, elements whose
// counts fit in the bytes the file holds (binary: each record's fixed-size part, lists counted
// as empty; ASCII: two characters per value), a vertex element with x, y and z and no list, and
// no obj_info grid (num_cols x num_rows) larger than the vertex count. Throws InputError naming
// the path and the field otherwise.
PlyHeader ParsePlyHeader(const std::string& path);

// ParsePlyHeader's vertex count (kept for callers that only check).
uint64_t CheckPlyHeader(const std::string& path);

// What raycarve takes from a PLY point cloud or mesh.
struct PlyData {
  std::vector<Eigen::Vector3f> xyz;
  std::vector<Eigen::Vector3f> normals;  // empty when the vertices have no nx, ny, nz
  std::vector<Eigen::Matrix<uint8_t, 3, 1>> rgb;  // empty when they have no red, green, blue
  std::vector<Eigen::Vector3i> triangles;  // the faces' polygons as fans
};

// Reads a PLY point cloud or mesh (ASCII or binary of either byte order, as COLMAP, PCL, MeshLab,
// CloudCompare and Open3D write them) without any library: the vertex element's x, y, z,
// optional normals (nx ny nz or normal_x ...) and colours (red green blue or r g b; integer
// types as 0-255, float types as 0-1), and the face element's vertex_indices (or vertex_index)
// lists, as triangle fans; other elements and properties are read past. Every count is checked
// against the bytes that remain before anything is sized from it. Throws InputError naming the
// path and what is wrong: a truncated or malformed body, a non-finite coordinate (with the
// vertex's index), a face that names a vertex the file does not have.
PlyData ReadPly(const std::string& path);

}  // namespace exporter
}  // namespace raycarve
